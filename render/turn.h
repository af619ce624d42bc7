/*
** turn.h — a view for imported models: turning an .obj/.off mesh before the Mapper
** (CONTRACT.md `--turn AZ,EL`; README "import views").
**
** This file contains code to turn an imported polygon mesh about its centre so that it is
** seen from the side and from above, as a solid, before it is put on the integer grid.
** Paper 003's Mapper (§2.2) projects along z from an eye on the negative z side and has
** no rotation: the 1974 operator typed in coordinates already in the pose to be drawn. A
** mesh from a modelling program usually comes face-on (a cube shows as a square), so the
** import gives it a pose first. This is host-side preparation of the input, in floating
** point, like the import's scaling; everything from the grid on stays exact.
**
** THE TURN, in the mesh's own frame (.obj/.off: x right, y up, the viewer on +z):
**   the model is seen as from an eye moved AZ degrees round to the right (about the
**   vertical y axis through the centre) and then EL degrees up. The vertices are turned
**   the other way, p' = c + Rx(EL) Ry(-AZ) (p - c), with c the centre of the bounding
**   box; the eye stays where the import puts it, and the import's bounding box, scaling
**   and fitted window are computed from the turned vertices (so the window follows the
**   turn). AZ = EL = 0 is the mesh as written.
** Default, without --turn: AZ = TURN_DEFAULT_AZ, EL = TURN_DEFAULT_EL, a three-quarter
** view in which a cube shows three faces.
*/
#ifndef T74_TURN_H
#define T74_TURN_H

#include "emu/status.h"
#include "render/scene.h"

#define TURN_DEFAULT_AZ 30.0    /* degrees round to the right */
#define TURN_DEFAULT_EL 20.0    /* degrees up */
#define TURN_LIMIT      3600.0  /* |AZ|, |EL| accepted (ten turns) */

/* Parse "AZ,EL" (two decimal numbers in degrees, |each| <= TURN_LIMIT). 0 on success. */
int turn_parse(const char *s, double *az, double *el);

/* Turn nv vertices xyz[3 nv] in place by AZ, EL about the centre of their bounding box. */
void turn_apply(double *xyz, int nv, double az, double el);

/* The import's turn: opts' --turn when given, else the three-quarter default. */
void turn_import(double *xyz, int nv, const struct scene_opts *opts);

#endif
