#!/bin/sh
# tools/docs.sh — `make docs`: the figures of README.md and docs/*.md regenerated from a run.
#
# A table lives between two markers on their own lines:
#     <!-- docs:NAME begin -->
#     ...
#     <!-- docs:NAME end -->
# and this script replaces what is between them:
#   - the deterministic tables (tools/figures.sh --list: 1974 seconds, words, pieces, dots),
#     from the tree's ./tube74; tests/test_docs.c checks that they are current;
#   - host-effects: what each effect costs a frame on this host (tools/bench_effects.sh),
#     headed with the
#     date, the machine and the commit it was measured on;
#   - speed-frame, speed-shaded, speed-process, speed-growth: the tables of `tube74 bench
#     speed` (its speed.md; SPEED_ARGS, default --quick --runs 5; speed-shaded: the scenes
#     with smooth shading against the shaded peer), same heading;
#   - accuracy: the table of `tube74 bench accuracy` (its accuracy.md; ACC_RUNS, default 3).
# DOCS_HOST=0 regenerates only the deterministic tables (seconds instead of minutes).
set -eu
cd "$(dirname "$0")/.."
B=build/docs
mkdir -p "$B"
HOST=${DOCS_HOST:-1}
make -s tube74 >/dev/null
if [ "$HOST" = 1 ]; then make -s build/bench/refbench >/dev/null; fi
RUNS=${RUNS:-5}
FRAMES=${FRAMES:-20}

machine() {
  cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n 1)
  echo "$(nproc) x ${cpu:-unknown CPU}, $(. /etc/os-release && echo "$PRETTY_NAME")"
}
heading() {
  echo "Measured $(date -u +%Y-%m-%d) on $(machine), load average $(cut -d' ' -f1 /proc/loadavg) at the start, commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown)$1."
  echo
}

for n in $(sh tools/figures.sh --list); do
  sh tools/figures.sh "$n" >"$B/$n.md"
done

if [ "$HOST" = 1 ]; then
  # host-effects: tools/bench_effects.sh, also run by make bench
  { heading ", $RUNS runs of --frames $FRAMES, medians"
    RUNS=$RUNS FRAMES=$FRAMES sh tools/bench_effects.sh "$B/effects"
  } >"$B/host-effects.md"

  # speed-*: the sections of bench speed's speed.md
  # shellcheck disable=SC2086
  ./tube74 bench speed ${SPEED_ARGS:---quick --runs 5} --out "$B/speed" >/dev/null
  for part in frame shaded process growth; do
    case $part in frame) h="One frame";; shaded) h="smooth shading";; process) h="Whole process";;
      growth) h="Growth";; esac
    { heading " (tube74 bench speed ${SPEED_ARGS:---quick --runs 5})"
      awk -v h="$h" '/^#/ { on = index($0, h) > 0; next } on' "$B/speed/speed.md" | sed '/./,$!d'
    } >"$B/speed-$part.md"
  done

  # accuracy: the summary table of bench accuracy
  ./tube74 bench accuracy --runs "${ACC_RUNS:-3}" --out "$B/accuracy" >/dev/null
  { heading " (tube74 bench accuracy --runs ${ACC_RUNS:-3})"
    awk '/^\|/ { on = 1; print; next } on { exit }' "$B/accuracy/accuracy.md"
  } >"$B/accuracy.md"
fi

# splice: every block whose table was made now is replaced; others are left as they are
python3 - "$B" README.md docs/*.md <<'EOF'
import os, re, sys
out, files = sys.argv[1], sys.argv[2:]
mark = re.compile(r'^<!-- docs:([a-z0-9-]+) begin -->\n(.*?)^<!-- docs:\1 end -->\n', re.M | re.S)
for path in files:
    text = open(path, encoding='utf-8').read()
    def repl(m):
        src = os.path.join(out, m.group(1) + '.md')
        if not os.path.exists(src):
            return m.group(0)
        body = open(src, encoding='utf-8').read()
        return '<!-- docs:%s begin -->\n%s<!-- docs:%s end -->\n' % (m.group(1), body, m.group(1))
    new = mark.sub(repl, text)
    if new != text:
        open(path + '.tmp', 'w', encoding='utf-8').write(new)
        os.replace(path + '.tmp', path)
        print('tools/docs.sh: updated', path)
EOF
