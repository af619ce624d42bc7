/*
** look.c — the storage tube's look over time (see look.h).
** Sources: paper 003 appendix (21 x 16.3 cm face, 400 x 300 points, stores 15 min or
** more, erases in under 500 ms); docs/hardware.md "The storage tube" (bright writing
** flash, stored traces brighter than the flood glow, green erase flash, write-through,
** charge spreading; P1 phosphor); rricharz/Tek4010's look constants (stored 0.7,
** write-through 0.5, bright spot 1.0 fading over about 1 s, glow 0.08).
**
** This file contains code to turn the events of a look (dots with their write times,
** write-through dots, erases) into a picture of the face at a given time.
**
** THE SPOT. A stored dot is a 2-D Gaussian of light, peak `stored`, sigma spot_mm, centred
** on the dot. Its sigma is sized from the dot pitch (0.525 mm x 0.543 mm): with
** 2 pi sigma^2 = pitch_x * pitch_y the light of one dot equals a pitch cell at the peak
** level, so an area with every dot lit shines evenly at `stored` while a lone dot is a
** round spot a little narrower than the pitch (FWHM 0.50 mm). Each pixel gets the MEAN of
** the spot over its area (exact, with erf, separable in x and y), so at any scale
**     sum over pixels of (value * pixel area) = peak * 2 pi sigma^2      (energy)
** up to the kernel's cut at 5 sigma (a part in 10^6).
**
** TIME. At time t, with a = t - t_write the age of a dot:
**   stored dot      amp = stored; with LOOK_FLASH plus (bright - stored)(1 - a/flash_s)
**                   while a < flash_s; with LOOK_FADE the charge spreads and dims:
**                   sigma^2 = spot^2 + spread^2 a/fade_s, amp *= spot^2/sigma^2 (the same
**                   light, spread wider) * exp(-a/fade_s).
**   write-through   amp = writethru (1 - a/writethru_s) while a < writethru_s; never stored.
**   erase at te     the whole face adds erase_level (1 - (t-te)/erase_s) while
**                   te <= t < te + erase_s; from te + erase_s on, every dot stored before
**                   then is gone. A dot given a time inside the last erase is written at
**                   its end, te + erase_s (the writing waits for the erase).
**   glow            added everywhere, always.
** Intensities add; look_colour maps them to P1 green, whitening above 1 (bloom).
**
** BOUNDED WORK. A fading spot widens without limit (tube=fade:0.001 an hour on), so a
** spot too wide for a LOOK_KERNEL_MAX kernel is drawn on a coarser grid and interpolated
** back (below, "wide spots"), and a spot whose peak is below LOOK_AMP_MIN is skipped: every
** look costs O(dots + pixels), whatever its constants. Spots that fit (every unfaded
** spot at every scale) are drawn exactly as described above.
*/
#include "display/look.h"

#include "display/image.h"
#include "emu/grow.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "display/outfile.h"
#include "display/sink.h"

#define LOOK_PI    3.14159265358979323846   /* M_PI is not in strict C11 */
#define LOOK_SQRT2 1.41421356237309504880

/* One row per constant: name, unit, default, range, source. */
const struct param_row look_param_rows[LP_NPARAM] = {
  [LP_STORED]      = { "stored", "1", 0.7, 0, 4, 0, "rricharz/Tek4010: stored intensity 0.7" },
  [LP_WRITETHRU]   = { "writethru", "1", 0.5, 0, 4, 0, "rricharz/Tek4010: write-through intensity 0.5" },
  [LP_WRITETHRU_S] = { "writethru_s", "s", 0.1, 1e-6, 1e6, 0,
                       "tuned by eye: not stored, so it fades at once (P1 persistence is tens "
                       "of ms; 0.1 s keeps a trace visible for a few frames)" },
  [LP_BRIGHT]      = { "bright", "1", 1.0, 0, 4, 0, "rricharz/Tek4010: bright writing spot 1.0" },
  [LP_FLASH_S]     = { "flash_s", "s", 1.0, 1e-6, 1e6, 0,
                       "rricharz/Tek4010: the bright spot fades over about 1 s (linear here)" },
  [LP_GLOW]        = { "glow", "1", 0.08, 0, 1, 0, "rricharz/Tek4010: background (flood-gun) glow 0.08" },
  [LP_ERASE_S]     = { "erase_s", "s", 0.45, 1e-6, 60, 0,
                       "paper 003 appendix: erases in under 500 ms (the Tektronix 613 takes "
                       "about 0.9 s)" },
  [LP_ERASE_LEVEL] = { "erase_level", "1", 1.0, 0, 4, 0,
                       "tuned by eye: the erase lights the whole face about as bright as the "
                       "writing spot, then it dies away" },
  [LP_PITCH_X_MM]  = { "pitch_x_mm", "mm", 0.525, 0.01, 10, 0, "paper 003 appendix: 210 mm / 400 points" },
  [LP_PITCH_Y_MM]  = { "pitch_y_mm", "mm", 0.5433, 0.01, 10, 0, "paper 003 appendix: 163 mm / 300 points" },
  [LP_SPOT_MM]     = { "spot_mm", "mm", 0.2130, 0.01, 10, 0,
                       "from the dot pitch: 2 pi sigma^2 = 0.525 x 0.543 mm^2, so a fully lit "
                       "area is as bright as one dot's peak (FWHM 0.50 mm)" },
  [LP_FADE_S]      = { "fade_s", "s", 900, 1e-3, 1e6, 0,
                       "paper 003 appendix: stores about 15 minutes or more (used only when "
                       "fading is asked: tube=fade:SECONDS or --look fade)" },
  [LP_FADE_SPREAD_MM] = { "fade_spread_mm", "mm", 0.53, 0, 10, 0,
                       "tuned by eye: in one fade time the charge spreads about one dot pitch" },
  [LP_P1_R]        = { "p1_r", "0..1", 80 / 255.0, 0, 1, 0,
                       "tuned by eye: P1 green (peak 525 nm), as display/image.c's dot colour" },
  [LP_P1_G]        = { "p1_g", "0..1", 1.0, 0, 1, 0, "tuned by eye: P1 green" },
  [LP_P1_B]        = { "p1_b", "0..1", 120 / 255.0, 0, 1, 0, "tuned by eye: P1 green" },
  [LP_BLOOM]       = { "bloom", "1", 0.6, 0, 4, 0,
                       "tuned by eye: light above intensity 1 whitens the spot" },
};

void look_params_default(struct look_params *p)
{
  param_defaults(look_param_rows, LP_NPARAM, p->v);
}

int look_params_set(struct look_params *p, const char *s, struct t74_error *err)
{
  const char *eq = strchr(s, '=');
  if (!eq) return t74_fail(err, T74_EINPUT, "look: expected NAME=VALUE, got `%s`", s);
  size_t n = (size_t)(eq - s);
  int k = param_find(look_param_rows, LP_NPARAM, s, n);
  if (k < 0) return t74_fail(err, T74_EINPUT, "look: unknown constant `%.*s`", (int)n, s);
  const struct param_row *r = &look_param_rows[k];
  if (param_parse(r, eq + 1, &p->v[k]) != PARAM_OK)
    return t74_fail(err, T74_EINPUT, "look: %s takes a number in %g .. %g %s, got `%s`",
                    r->name, r->min, r->max, r->unit, eq + 1);
  return T74_OK;
}

int look_params_list(const struct look_params *p, FILE *f)
{
  param_list(look_param_rows, LP_NPARAM, p->v, 16, f);
  return ferror(f) ? T74_EIO : T74_OK;
}

/* ---- events ------------------------------------------------------------------------ */

enum { EV_STORED, EV_WRITETHRU };

struct look_ev {
  double t;             /* 1974 seconds */
  int16_t x, y;         /* tube dot */
  uint8_t kind;         /* EV_STORED or EV_WRITETHRU */
};

struct look {
  struct look_params p;
  unsigned flags;       /* LOOK_FLASH | LOOK_FADE */
  struct look_ev *ev;   /* dots, in the order given */
  size_t nev, cap;
  size_t nstored;       /* EV_STORED events among them */
  size_t *stored_ix;    /* index into ev[] of each stored event, in order (look_event) */
  size_t scap;
  double *erase;        /* erase start times, in the order given */
  size_t nerase, ecap;
};

struct look *look_new(const struct look_params *p, unsigned flags)
{
  struct look *l = calloc(1, sizeof *l);
  if (!l) return NULL;
  l->p = *p;
  l->flags = flags;
  return l;
}

void look_free(struct look *l)
{
  if (!l) return;
  free(l->ev);
  free(l->stored_ix);
  free(l->erase);
  free(l);
}

void look_clear(struct look *l)
{
  l->nev = l->nstored = l->nerase = 0;
}

static int add_ev(struct look *l, int x, int y, double t, int kind)
{
  if (x < 0 || x >= TUBE_W || y < 0 || y >= TUBE_H) return T74_EINPUT;
  /* A dot given while the last erase is under way is written when it is over: a tube
     being erased stores nothing, and a 4014 host pads the erase (or the terminal holds
     its input) rather than lose what follows ESC FF. Without this, a stream that begins
     with an erase lost every dot of its first erase_s. */
  if (l->nerase) {
    double te = l->erase[l->nerase - 1], tend = te + l->p.v[LP_ERASE_S];
    if (t >= te && t < tend) t = tend;
  }
  if (!t74_grow((void **)&l->ev, &l->cap, l->nev + 1, sizeof *l->ev)) return T74_EIO;
  if (kind == EV_STORED) {
    if (!t74_grow((void **)&l->stored_ix, &l->scap, l->nstored + 1, sizeof *l->stored_ix)) return T74_EIO;
    l->stored_ix[l->nstored++] = l->nev;
  }
  struct look_ev *e = &l->ev[l->nev++];
  e->t = t;
  e->x = (int16_t)x;
  e->y = (int16_t)y;
  e->kind = (uint8_t)kind;
  return T74_OK;
}

int look_dot(struct look *l, int x, int y, double t) { return add_ev(l, x, y, t, EV_STORED); }

int look_writethrough(struct look *l, int x, int y, double t)
{
  return add_ev(l, x, y, t, EV_WRITETHRU);
}

int look_erase(struct look *l, double t)
{
  if (!t74_grow((void **)&l->erase, &l->ecap, l->nerase + 1, sizeof *l->erase)) return T74_EIO;
  l->erase[l->nerase++] = t;
  return T74_OK;
}

size_t look_count(const struct look *l) { return l->nstored; }

int look_event(const struct look *l, size_t k, int *x, int *y, double *t)
{
  if (k >= l->nstored) return T74_EINPUT;
  const struct look_ev *e = &l->ev[l->stored_ix[k]];
  *x = e->x;
  *y = e->y;
  *t = e->t;
  return T74_OK;
}

double look_settled(const struct look *l)
{
  double end = 0;
  for (size_t k = 0; k < l->nev; k++) {
    const struct look_ev *e = &l->ev[k];
    double d = e->kind == EV_WRITETHRU ? l->p.v[LP_WRITETHRU_S]
             : (l->flags & LOOK_FLASH) ? l->p.v[LP_FLASH_S] : 0;
    if (e->t + d > end) end = e->t + d;
  }
  for (size_t k = 0; k < l->nerase; k++)
    if (l->erase[k] + l->p.v[LP_ERASE_S] > end) end = l->erase[k] + l->p.v[LP_ERASE_S];
  return end;
}

const struct look_params *look_get_params(const struct look *l) { return &l->p; }
unsigned look_flags(const struct look *l) { return l->flags; }

/* ---- the spot kernel --------------------------------------------------------------- */

/* One axis of a dot's spot at scale s: dot (x) covers pixels x*s .. x*s+s-1 and its centre
** is at x*s + s/2 (pixel units). k[m + R], m = -R .. s-1+R, is the mean of the unit-peak
** Gaussian (sigma mm) over pixel x*s + m, whose width is pitch/s mm. */
struct axis {
  int R;                /* pixels of margin each side of the dot's own s pixels */
  float *k;             /* s + 2R values */
};

static int axis_make(struct axis *a, double sigma_mm, double pitch_mm, int s)
{
  double px = pitch_mm / s;                           /* pixel width, mm */
  a->R = (int)ceil(5.0 * sigma_mm / px);
  a->k = malloc((size_t)(s + 2 * a->R) * sizeof *a->k);
  if (!a->k) return -1;
  double c = s / 2.0;                                 /* centre, pixels from x*s */
  double f = sigma_mm * sqrt(LOOK_PI / 2) / px;          /* (1/px) * integral scale */
  for (int m = -a->R; m < s + a->R; m++) {
    double u0 = (m - c) * px / (sigma_mm * LOOK_SQRT2);
    double u1 = (m + 1 - c) * px / (sigma_mm * LOOK_SQRT2);
    a->k[m + a->R] = (float)(f * (erf(u1) - erf(u0)));
  }
  return 0;
}

/* Add amp * spot(ax, ay) for dot (x, y) into out (W x H, row 0 = top). */
static void stamp(float *out, int W, int H, int s, int x, int y, double amp,
                  const struct axis *ax, const struct axis *ay)
{
  int X0 = x * s - ax->R, Y0 = (TUBE_H - 1 - y) * s - ay->R;   /* top-left of the kernel */
  int nx = s + 2 * ax->R, ny = s + 2 * ay->R;
  for (int j = 0; j < ny; j++) {
    int Y = Y0 + j;
    if (Y < 0 || Y >= H) continue;
    /* the spot is symmetric about the dot's centre, so row j of the picture (counted
       downward) uses ay->k[j] as it stands */
    float wy = (float)amp * ay->k[j];
    float *row = out + (size_t)Y * (size_t)W;
    for (int i = 0; i < nx; i++) {
      int X = X0 + i;
      if (X >= 0 && X < W) row[X] += wy * ax->k[i];
    }
  }
}

/* ---- wide spots: coarser grids ----------------------------------------------------- */

/* A fading spot widens without bound as it ages (sigma^2 grows with a/fade_s), and a
** kernel 5 sigma wide at full resolution would cost its width squared per dot. So a
** spot whose kernel would be more than LOOK_KERNEL_MAX pixels across a side is drawn on
** a coarser grid instead: grid L has cells of 2^L x 2^L output pixels, chosen as the
** finest on which the kernel is at most LOOK_KERNEL_MAX cells a side, and each cell gets
** the exact mean of the spot over the cell (erf, as at full resolution). At the end each
** grid is added onto the picture by bilinear interpolation between cell centres: on a
** coarse grid sigma is at least LOOK_KERNEL_MAX/10 cells, where interpolating a Gaussian
** errs by under 2% of its (already dim) peak. The work per dot is bounded by
** (2 LOOK_KERNEL_MAX + 2)^2, the work per grid by the picture's pixels: the whole look
** costs O(dots + pixels), whatever fade_s, the age or the spread.
** A dot whose peak has faded below LOOK_AMP_MIN (1/256 of one 8-bit step of the P1
** colour) is not drawn at all: its whole light is below what a pixel can show. */
#define LOOK_KERNEL_MAX 32      /* kernel radius, in cells of its grid (5 sigma) */
#define LOOK_LEVELS     16      /* grids 0..15: 2^15 output pixels per cell > any picture */
#define LOOK_AMP_MIN    (1.0 / (256.0 * 256.0))   /* dimmer peaks are not drawn */

struct grid {
  int f;                        /* output pixels per cell side: 2^L */
  int w, h;                     /* cells: ceil(W / f) x ceil(H / f) */
  float *v;                     /* w * h cell values, row 0 at the top; NULL until used */
};

/* The mean of a unit-peak Gaussian (sigma sp, centre c, in output pixels) over the cells
** of side f that it reaches (5 sigma), clipped to 0..n-1: k[0..*cnt) for cells *first... */
static int coarse_axis(double c, double sp, int f, int n, float *k, int *first, int *cnt)
{
  double lo = floor((c - 5 * sp) / f), hi = floor((c + 5 * sp) / f);
  if (lo < 0) lo = 0;
  if (hi > n - 1) hi = n - 1;
  if (hi < lo) return 0;
  *first = (int)lo;
  *cnt = (int)(hi - lo) + 1;
  double g = sp * sqrt(LOOK_PI / 2) / f;                 /* (1/f) * the integral's scale */
  for (int m = 0; m < *cnt; m++) {
    double u0 = ((*first + m) * (double)f - c) / (sp * LOOK_SQRT2);
    double u1 = ((*first + m + 1) * (double)f - c) / (sp * LOOK_SQRT2);
    k[m] = (float)(g * (erf(u1) - erf(u0)));
  }
  return 1;
}

/* Add amp * spot(sigma) for dot (x, y) at scale s onto grid g (allocated on first use). */
static int stamp_coarse(struct grid *g, int s, int x, int y, double amp, double sig_mm,
                        const double *v)
{
  if (!g->v && !(g->v = calloc((size_t)g->w * (size_t)g->h, sizeof *g->v))) return -1;
  float kx[2 * LOOK_KERNEL_MAX + 4], ky[2 * LOOK_KERNEL_MAX + 4];
  int x0, nx, y0, ny;
  double cx = x * s + s / 2.0, cy = (TUBE_H - 1 - y) * s + s / 2.0;   /* output pixels */
  if (!coarse_axis(cx, sig_mm * s / v[LP_PITCH_X_MM], g->f, g->w, kx, &x0, &nx)) return 0;
  if (!coarse_axis(cy, sig_mm * s / v[LP_PITCH_Y_MM], g->f, g->h, ky, &y0, &ny)) return 0;
  for (int j = 0; j < ny; j++) {
    float wy = (float)amp * ky[j];
    float *row = g->v + (size_t)(y0 + j) * (size_t)g->w + (size_t)x0;
    for (int i = 0; i < nx; i++) row[i] += wy * kx[i];
  }
  return 0;
}

/* Output pixel k's place between the centres of cells i0 and i1 (of n, f pixels a cell),
** clamped at the edges; t is the weight of i1. */
static void grid_cell(int k, double f, int n, int *i0, int *i1, double *t)
{
  double u = (k + 0.5) / f - 0.5;
  int c = (int)floor(u);
  *t = u - c;
  *i0 = c < 0 ? 0 : c > n - 1 ? n - 1 : c;
  *i1 = c + 1 > n - 1 ? n - 1 : c + 1;
}

/* Add grid g onto out (W x H) by bilinear interpolation between cell centres; the columns'
** cells and weights are found once, not again on every row. Returns -1 when out of host
** memory, else 0. */
static int grid_add(const struct grid *g, float *out, int W, int H)
{
  int *ci = malloc(2 * (size_t)W * sizeof *ci);
  double *ct = malloc((size_t)W * sizeof *ct);
  if (!ci || !ct) { free(ci); free(ct); return -1; }
  for (int X = 0; X < W; X++) grid_cell(X, g->f, g->w, &ci[2 * X], &ci[2 * X + 1], &ct[X]);
  for (int Y = 0; Y < H; Y++) {
    int j0, j1;
    double ty;
    grid_cell(Y, g->f, g->h, &j0, &j1, &ty);
    const float *r0 = g->v + (size_t)j0 * (size_t)g->w, *r1 = g->v + (size_t)j1 * (size_t)g->w;
    float *o = out + (size_t)Y * (size_t)W;
    for (int X = 0; X < W; X++) {
      int i0 = ci[2 * X], i1 = ci[2 * X + 1];
      double tx = ct[X];
      o[X] += (float)((1 - ty) * ((1 - tx) * r0[i0] + tx * r0[i1]) +
                      ty * ((1 - tx) * r1[i0] + tx * r1[i1]));
    }
  }
  free(ci);
  free(ct);
  return 0;
}

/* The grid for a spot of sigma sig_mm at scale s: 0 when its kernel fits LOOK_KERNEL_MAX
** output pixels (drawn exactly, as an unfaded spot), else the finest coarse grid. */
static int spot_level(double sig_mm, int s, const double *v)
{
  double px = fmin(v[LP_PITCH_X_MM], v[LP_PITCH_Y_MM]) / s;     /* the smaller pixel, mm */
  double r = 5.0 * sig_mm / px;                                  /* kernel radius, pixels */
  int L = 0;
  while (L < LOOK_LEVELS - 1 && r > LOOK_KERNEL_MAX) { r /= 2; L++; }
  return L;
}

/* ---- rendering --------------------------------------------------------------------- */

int look_intensity(const struct look *l, double t, int s, float *out)
{
  if (s < 1 || s > LOOK_SCALE_MAX) return T74_EINPUT;
  const double *v = l->p.v;
  int W = TUBE_W * s, H = TUBE_H * s;
  size_t npx = (size_t)W * (size_t)H;

  /* the erases: when the face was last cleared, and whether one is under way */
  double cleared = -INFINITY, flash = 0;
  for (size_t k = 0; k < l->nerase; k++) {
    double te = l->erase[k], tend = te + v[LP_ERASE_S];
    if (tend <= t && tend > cleared) cleared = tend;
    if (te <= t && t < tend) {
      double f = v[LP_ERASE_LEVEL] * (1 - (t - te) / v[LP_ERASE_S]);
      if (f > flash) flash = f;
    }
  }
  float base = (float)(v[LP_GLOW] + flash);
  for (size_t k = 0; k < npx; k++) out[k] = base;

  struct axis ax0, ay0;                  /* the unfaded spot, same for every dot */
  if (axis_make(&ax0, v[LP_SPOT_MM], v[LP_PITCH_X_MM], s)) return T74_EIO;
  if (axis_make(&ay0, v[LP_SPOT_MM], v[LP_PITCH_Y_MM], s)) { free(ax0.k); return T74_EIO; }
  struct grid grids[LOOK_LEVELS];        /* grids[0] is unused: level 0 is out itself */
  for (int L = 0; L < LOOK_LEVELS; L++) {
    grids[L].f = 1 << L;
    grids[L].w = (W + grids[L].f - 1) / grids[L].f;
    grids[L].h = (H + grids[L].f - 1) / grids[L].f;
    grids[L].v = NULL;
  }
  int st = T74_OK;
  int fade = (l->flags & LOOK_FADE) != 0;
  double spot2 = v[LP_SPOT_MM] * v[LP_SPOT_MM];
  int L0 = spot_level(v[LP_SPOT_MM], s, v);   /* a huge spot_mm alone may need a grid */
  for (size_t k = 0; k < l->nev && st == T74_OK; k++) {
    const struct look_ev *e = &l->ev[k];
    if (e->t > t) continue;              /* not written yet */
    double a = t - e->t;                 /* age */
    double amp, sig = v[LP_SPOT_MM];
    if (e->kind == EV_WRITETHRU) {
      if (a >= v[LP_WRITETHRU_S]) continue;
      amp = v[LP_WRITETHRU] * (1 - a / v[LP_WRITETHRU_S]);
    } else {
      if (e->t < cleared) continue;      /* erased */
      amp = v[LP_STORED];
      if ((l->flags & LOOK_FLASH) && a < v[LP_FLASH_S])
        amp += (v[LP_BRIGHT] - v[LP_STORED]) * (1 - a / v[LP_FLASH_S]);
      if (fade) {
        double u = a / v[LP_FADE_S];     /* ages in fade times: finite, fade_s >= 1e-3 */
        double dim = exp(-u);
        if (amp * dim < LOOK_AMP_MIN) continue;   /* then also far below once spread */
        double sp = v[LP_FADE_SPREAD_MM];
        double sig2 = spot2 + sp * sp * u;
        amp *= spot2 / sig2 * dim;
        sig = sqrt(sig2);
      }
    }
    if (amp < LOOK_AMP_MIN) continue;
    int L = sig == v[LP_SPOT_MM] ? L0 : spot_level(sig, s, v);
    if (L > 0) {                         /* wide: onto its coarse grid */
      if (stamp_coarse(&grids[L], s, e->x, e->y, amp, sig, v)) st = T74_EIO;
      continue;
    }
    if (sig == v[LP_SPOT_MM]) { stamp(out, W, H, s, e->x, e->y, amp, &ax0, &ay0); continue; }
    struct axis ax, ay;
    if (axis_make(&ax, sig, v[LP_PITCH_X_MM], s)) { st = T74_EIO; break; }
    if (axis_make(&ay, sig, v[LP_PITCH_Y_MM], s)) { free(ax.k); st = T74_EIO; break; }
    stamp(out, W, H, s, e->x, e->y, amp, &ax, &ay);
    free(ax.k);
    free(ay.k);
  }
  for (int L = 1; L < LOOK_LEVELS; L++) {
    if (grids[L].v && st == T74_OK && grid_add(&grids[L], out, W, H)) st = T74_EIO;
    free(grids[L].v);
  }
  free(ax0.k);
  free(ay0.k);
  return st;
}

void look_colour(const struct look_params *p, float I, uint8_t rgba[4])
{
  double bloom = I > 1 ? (I - 1) * p->v[LP_BLOOM] : 0;
  for (int c = 0; c < 3; c++) {
    double x = I * p->v[LP_P1_R + c] + bloom;
    x = x < 0 ? 0 : x > 1 ? 1 : x;
    rgba[c] = (uint8_t)lrint(x * 255);
  }
  rgba[3] = 255;
}

int look_render(const struct look *l, double t, int s, uint8_t *rgba)
{
  if (s < 1 || s > LOOK_SCALE_MAX) return T74_EINPUT;
  size_t npx = (size_t)TUBE_W * s * (size_t)TUBE_H * s;
  float *I = malloc(npx * sizeof *I);
  if (!I) return T74_EIO;
  int st = look_intensity(l, t, s, I);
  if (st == T74_OK)
    for (size_t k = 0; k < npx; k++) look_colour(&l->p, I[k], rgba + 4 * k);
  free(I);
  return st;
}

/* ---- PNG --------------------------------------------------------------------------- */

struct rgba_rows { const uint8_t *rgba; int w; };

static void rgba_row(void *ctx, int r, uint8_t *rgb)
{
  const struct rgba_rows *p = ctx;
  const uint8_t *src = p->rgba + (size_t)r * (size_t)p->w * 4;
  for (int x = 0; x < p->w; x++) memcpy(rgb + 3 * x, src + 4 * x, 3);
}

int look_png_rgba_to(const uint8_t *rgba, int w, int h, struct outfile *o,
                     struct t74_error *err)
{
  struct rgba_rows p = { rgba, w };
  return image_write_rgb_png_to(w, h, rgba_row, &p, o, err);
}

int look_png_rgba(const uint8_t *rgba, int w, int h, const char *path, struct t74_error *err)
{
  struct outfile *o;
  if (outfile_open(&o, path, err) != T74_OK) return err->status;
  return look_png_rgba_to(rgba, w, h, o, err);
}

int look_write_png_to(const struct look *l, double t, int s, struct outfile *o,
                      struct t74_error *err)
{
  const char *path = outfile_path(o);
  if (s < 1 || s > LOOK_SCALE_MAX) {
    outfile_abort(o);
    return t74_fail(err, T74_EINPUT, "look: scale %d is outside 1..%d", s, LOOK_SCALE_MAX);
  }
  size_t n = (size_t)TUBE_W * s * (size_t)TUBE_H * s * 4;
  uint8_t *rgba = malloc(n);
  if (!rgba) {
    t74_fail(err, T74_EIO, "%s: out of memory", path);
    outfile_abort(o);
    return T74_EIO;
  }
  int st = look_render(l, t, s, rgba);
  if (st != T74_OK) {
    free(rgba);
    t74_fail(err, st, "%s: cannot render the tube's look", path);
    outfile_abort(o);
    return st;
  }
  st = look_png_rgba_to(rgba, TUBE_W * s, TUBE_H * s, o, err);
  free(rgba);
  return st;
}

int look_write_png(const struct look *l, double t, int s, const char *path,
                   struct t74_error *err)
{
  if (s < 1 || s > LOOK_SCALE_MAX)
    return t74_fail(err, T74_EINPUT, "look: scale %d is outside 1..%d", s, LOOK_SCALE_MAX);
  struct outfile *o;
  if (outfile_open(&o, path, err) != T74_OK) return err->status;
  return look_write_png_to(l, t, s, o, err);
}
