#!/bin/sh
# `make demo`'s FreeCAD part (packaging/demo-freecad) under Xvfb with HG_DEMO_EXIT=1, as the
# user running the tests and, when that is root, also as an unprivileged user (nobody, a
# fresh HOME): FreeCAD must open the demo with its panel and exit 0 both times.
#   check_demo.sh SOURCE_DIR BUILD_DIR
set -eu
source=$1; build=$2
run() {  # HOME, then the command prefix
  home=$1; shift
  HOME="$home" HG_DEMO_EXIT=1 timeout -k 10 240 "$@" xvfb-run -a -s "-screen 0 1280x1024x24" \
    "$source/packaging/demo-freecad" "$build" "$source" > "$home/demo.log" 2>&1 || {
    echo "demo failed ($*):"; cat "$home/demo.log"; return 1; }
  grep -q "HapticGrasp demo: panel open" "$home/demo.log" || { echo "no panel ($*):"; cat "$home/demo.log"; return 1; }
  echo "demo ok${*:+ via: $*}"
}
home=$(mktemp -d); trap 'rm -rf "$home" "${other:-}"' EXIT INT TERM
run "$home"
if [ "$(id -u)" = 0 ] && command -v setpriv >/dev/null; then
  other=$(mktemp -d); chown 65534:65534 "$other"; chmod 755 "$other"
  run "$other" setpriv --reuid=65534 --regid=65534 --clear-groups env HOME="$other"
fi
