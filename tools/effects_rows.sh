# tools/effects_rows.sh — sourced by tools/figures.sh (1974 time) and tools/bench_effects.sh
# (host time a frame): the scenes and the effect rows of "what each effect costs", one list
# so that the two tables have the same rows. Rows are one a line; aa=none is the plain render.
FX_SCENES="fig5 sphere street fig6-building"
FX_ROWS="aa=none
edges=on
smooth=phong
smooth=phong contour=1.0
smooth=prop:0.15
shadows=on
aa=multiscan filter=box n=3
aa=multiscan filter=gauss n=3
aa=area depth=2
aa=super super=3
aa=exact
smooth=phong contour=1.0 edges=on shadows=on
smooth=phong contour=1.0 edges=on shadows=on aa=multiscan n=3"
