#!/bin/sh
# text2c.sh FILE NAME — FILE as two C strings for the program to write out: NAME_head, the
# lines before the one that holds only "<!-- data -->", and NAME_tail, the lines after it
# (the teaching page cli/teach_page.html; the Makefile writes the result into the build
# folder). Backslashes, quotes, tabs and question marks (no trigraphs) are escaped; a file
# without exactly one marker line is refused.
set -eu
marker='<!-- data -->'
if [ "$(grep -cx -- "$marker" "$1")" != 1 ]; then
  echo "$1: needs exactly one line '$marker'" >&2
  exit 1
fi
esc() {
  sed -e 's/\\/\\\\/g' -e 's/"/\\"/g' -e 's/?/\\?/g' -e 's/	/\\t/g' -e 's/^/  "/' -e 's/$/\\n"/'
}
echo "/* generated from $1 by tools/text2c.sh: edit that file */"
echo "const char ${2}_head[] ="
sed "/^$marker\$/,\$d" "$1" | esc
echo '  "";'
echo "const char ${2}_tail[] ="
sed "1,/^$marker\$/d" "$1" | esc
echo '  "";'
