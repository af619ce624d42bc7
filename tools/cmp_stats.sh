#!/bin/sh
# cmp_stats.sh — checks that two tube74 binaries report the same figures.
# Renders every scene in scenes/ and build/bench/g1000.s74, g10000.s74 (tools/mkgrowth.py)
# with each binary and compares the --stats JSON byte for byte, minus host_seconds and
# frame_seconds (host timings). Used for issue 12 (counting overhead): a change to how the
# 1974 operations are counted must leave hitac10_seconds, exact_hitac10_seconds, the
# operations counts and every other field as they were.
# CMP_FULL=1 (issue 19, speed work on the 1974 engine) widens the check: the exit status,
# the PNG, `--dump ids` (not at 100,000 faces: a 16-bit PGM) and `--dump tables` too, every
# run with `--frames 2` (the frame before must not change what the written one gives), each
# scene also with `--arith hitac`, the shipped scenes also on the default core, and besides
# scenes/*.s74: scenes/cube.obj with --engine 1974, the boxes of `tube74 bench speed`
# (tools/mkgrowth.py --obj: 1,000, 10,000, 100,000 faces) and its interpenetrating
# triangles (tools/mktris.py: 160 .. 2,560).
# CMP_POINTS=1 (issue 19, speed work on the points engine) runs instead the points engine on
# every shipped scene, scenes/cube.obj, the bench's boxes (1,000, 10,000) and triangles
# (160 .. 640), each at --frames 1 and --frames 3, five scenes under two other effect mixes,
# comparing the exit status, --stats, the
# PNG and the ids, grey and points dumps.
# CMP_FX=1 (issue 19, speed work on the effects) runs instead every shipped scene with the
# 1974 engine under nine effect mixes, and lprism, the sphere and t1-d with every face's
# vertices given in the other order (an open surface or a closed one turned from the eye)
# under five smoothing mixes with both engines, each at --frames 2, comparing the exit
# status, --stats, the PNG, the ids (and the grey dump where points runs).
# Usage: tools/cmp_stats.sh OLD_BINARY NEW_BINARY [WORKDIR]; exit 0 when all agree.
set -u
old=$1; new=$2; dir=${3:-build/cmp_stats}
full=${CMP_FULL:-0}
pts=${CMP_POINTS:-0}
fx=${CMP_FX:-0}
mkdir -p build/bench "$dir/old" "$dir/new"
for n in 1000 10000; do
  [ -f build/bench/g$n.s74 ] || python3 tools/mkgrowth.py $n >build/bench/g$n.s74
done
if [ "$full" = 1 ]; then
  for n in 1000 10000 100000; do
    [ -f build/bench/boxes$n.obj ] || python3 tools/mkgrowth.py $n --obj >build/bench/boxes$n.obj
  done
  for n in 160 320 640 1280 2560; do
    [ -f build/bench/tris$n.s74 ] || python3 tools/mktris.py $n >build/bench/tris$n.s74
  done
fi

# after one side's run: its exit status, and its --stats without the host timings
side_done() {
  echo "$1" >"$2.rc"
  sed -E 's/"(host_seconds|frame_seconds)": *[-0-9.eE+]+,? *//g' "$2.json" \
    >"$2.cmp" 2>/dev/null || : >"$2.cmp"
}

# the two sides of run TAG compared: status, stats and the outputs EXT... either side wrote
judge() {
  b=$1; shift
  count=$((count + 1))
  what=""
  cmp -s "$dir/old/$b.rc" "$dir/new/$b.rc" || what="$what status"
  if [ "$(cat "$dir/old/$b.rc")" = 0 ] && [ ! -s "$dir/old/$b.cmp" ]; then what="$what no-stats"; fi
  cmp -s "$dir/old/$b.cmp" "$dir/new/$b.cmp" || what="$what stats"
  for e in "$@"; do
    if [ -f "$dir/old/$b.$e" ] || [ -f "$dir/new/$b.$e" ]; then
      cmp -s "$dir/old/$b.$e" "$dir/new/$b.$e" || what="$what $e"
    fi
  done
  [ -z "$what" ] || { echo "differs ($what ): $b $judged"; bad=$((bad + 1)); }
}

# one run of each binary: SCENE TAG EXTRA...; the outputs compared are listed in $dir/*/TAG.*
bad=0; count=0
run() {
  g=$1; b=$2; shift 2
  for side in old new; do
    eval bin=\$$side
    o="$dir/$side/$b"
    rm -f "$o".json "$o".png "$o".ids "$o".tables "$o".rc
    if [ "$full" = 1 ]; then
      case $g in *100000*) ids="" ;; *) ids="--dump ids=$o.ids" ;; esac
      # the tables apart: a trace takes the Segment Generator's general path (seg_convex)
      "$bin" render "$g" --dump tables="$o.tables" "$@" >/dev/null 2>&1
      # shellcheck disable=SC2086
      "$bin" render "$g" --stats "$o.json" -o "$o.png" $ids --frames 2 "$@" >/dev/null 2>&1
    else
      "$bin" render "$g" --stats "$o.json" -o "$o.png" "$@" >/dev/null 2>&1
    fi
    side_done $? "$o"
  done
  judged="$*"
  if [ "$full" = 1 ]; then judge "$b" png ids tables; else judge "$b"; fi
}

# one points-engine run of each binary (under CMP_FX, of the engine the extra arguments
# name): SCENE TAG EXTRA...
run_points() {
  g=$1; b=$2; shift 2
  for side in old new; do
    eval bin=\$$side
    o="$dir/$side/$b"
    rm -f "$o".json "$o".png "$o".ids "$o".grey "$o".points "$o".rc
    if [ "$fx" = 1 ]; then
      # the engine is in the arguments; grey and points dumps only where points runs
      case " $* " in
        *" points "*) "$bin" render "$g" --stats "$o.json" -o "$o.png" --dump ids="$o.ids" \
                        --dump grey="$o.grey" "$@" >/dev/null 2>&1 ;;
        *) "$bin" render "$g" --stats "$o.json" -o "$o.png" --dump ids="$o.ids" "$@" \
             >/dev/null 2>&1 ;;
      esac
    else
      "$bin" render "$g" --engine points --stats "$o.json" -o "$o.png" --dump ids="$o.ids" \
        --dump grey="$o.grey" --dump points="$o.points" "$@" >/dev/null 2>&1
    fi
    side_done $? "$o"
  done
  judged="$*"
  judge "$b" png ids grey points
}

if [ "$fx" = 1 ]; then
  # run_points's comparisons, with the engine given in the extra arguments
  for g in scenes/*.s74; do
    b=$(basename "$g"); k=0
    for mix in "" "aa=multiscan" "aa=area" "aa=super" "aa=multiscan smooth=prop:0.15 contour=0.5" \
               "aa=area smooth=gouraud shadows=on" "aa=super smooth=phong contour=1.0 shadows=on" \
               "edges=on smooth=fixed:0.15 contour=0.5" "shadows=on aa=multiscan"; do
      k=$((k + 1))
      if [ -n "$mix" ]; then
        run_points "$g" "$b.fx$k" --engine 1974 --core 268435456 --frames 2 --effects "$mix"
      else
        run_points "$g" "$b.fx$k" --engine 1974 --core 268435456 --frames 2
      fi
    done
  done
  mkdir -p "$dir/rev"
  for g in scenes/lprism.s74 scenes/sphere.s74 scenes/t1-d.s74; do
    b=$(basename "$g" .s74)
    awk '$1 == "face" { printf "face %s", $2; for (i = NF; i > 2; i--) printf " %s", $i; print ""; next } { print }' \
      "$g" >"$dir/rev/$b-rev.s74"
    k=0
    for mix in "halftone=3x3 smooth=phong contour=1.0" "halftone=3x3 smooth=prop:0.15 contour=0.5" \
               "halftone=3x3 smooth=fixed:0.15" "halftone=4x4 smooth=gouraud contour=0.5 shadows=on" \
               "smooth=fixed:0.5 aa=super"; do
      k=$((k + 1))
      for eng in 1974 points; do
        run_points "$dir/rev/$b-rev.s74" "$b-rev.$eng.$k" --engine $eng --frames 2 --effects "$mix"
      done
    done
  done
  echo "$count runs, $bad differ"
  [ "$bad" -eq 0 ]
  exit
fi

if [ "$pts" = 1 ]; then
  for n in 1000 10000; do
    [ -f build/bench/boxes$n.obj ] || python3 tools/mkgrowth.py $n --obj >build/bench/boxes$n.obj
  done
  for n in 160 320 640; do
    [ -f build/bench/tris$n.s74 ] || python3 tools/mktris.py $n >build/bench/tris$n.s74
  done
  for g in scenes/*.s74 scenes/cube.obj build/bench/boxes1000.obj build/bench/boxes10000.obj \
           build/bench/tris160.s74 build/bench/tris320.s74 build/bench/tris640.s74; do
    b=$(basename "$g")
    run_points "$g" "$b.p1" --frames 1
    run_points "$g" "$(basename "$g").p3" --frames 3
  done
  for g in scenes/fig5.s74 scenes/fig6-room.s74 scenes/lprism.s74 scenes/sphere.s74 \
           scenes/street.s74; do
    run_points "$g" "$(basename "$g").fxa" --frames 2 --effects "aa=super shadows=on"
    run_points "$g" "$(basename "$g").fxb" --frames 2 \
      --effects "halftone=4x4 smooth=gouraud contour=0.5 shadows=on"
  done
  echo "$count runs, $bad differ"
  [ "$bad" -eq 0 ]
  exit
fi

for g in scenes/*.s74 build/bench/g1000.s74 build/bench/g10000.s74; do
  b=$(basename "$g")
  run "$g" "$b" --core 268435456
  if [ "$full" = 1 ]; then
    run "$g" "$b.hitac" --core 268435456 --arith hitac
    case $g in scenes/*) run "$g" "$b.16k" ;; esac
  fi
done
if [ "$full" = 1 ]; then
  run scenes/cube.obj cube.obj --engine 1974
  run scenes/cube.obj cube.obj.hitac --engine 1974 --arith hitac
  for g in build/bench/boxes1000.obj build/bench/boxes10000.obj build/bench/boxes100000.obj \
           build/bench/tris160.s74 build/bench/tris320.s74 build/bench/tris640.s74 \
           build/bench/tris1280.s74 build/bench/tris2560.s74; do
    b=$(basename "$g")
    t=""; case $g in *.obj) t="--turn 0,0" ;; esac
    # shellcheck disable=SC2086
    run "$g" "$b" --engine 1974 --core 268435456 $t
    # shellcheck disable=SC2086
    run "$g" "$b.hitac" --engine 1974 --core 268435456 $t --arith hitac
  done
fi
echo "$count runs, $bad differ"
[ "$bad" -eq 0 ]
