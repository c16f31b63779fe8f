#!/bin/sh
# Runs a test module in the real FreeCAD GUI under Xvfb against the built workbench, in a
# throw-away HOME whose FreeCAD Mod folder links to the build tree's package.
#   run_freecad_gui.sh FREECAD PACKAGE_DIR TEST_MODULE
freecad="$1"; package="$2"; module="$3"
home=$(mktemp -d)
trap 'rm -rf "$home"' EXIT INT TERM
mkdir -p "$home/.local/share/FreeCAD/Mod"
ln -s "$package" "$home/.local/share/FreeCAD/Mod/HapticGrasp"
HOME="$home" QTWEBENGINE_DISABLE_SANDBOX=1 timeout -k 10 300 \
  xvfb-run -a -s "-screen 0 1280x1024x24" "$freecad" -t "$module"
