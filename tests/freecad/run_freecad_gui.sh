#!/bin/sh
# Runs a test module in the real FreeCAD GUI under Xvfb against the built workbench, in a
# throw-away HOME whose FreeCAD Mod folder links to the build tree's addon
# (build/freecad/HapticGrasp).
#   run_freecad_gui.sh FREECAD ADDON_DIR TEST_MODULE[.Class[.test]]
# The test modules are in the package freecad.hapticgrasp: a short name gets that prefix.
freecad="$1"; addon="$2"; module="$3"
case "$module" in freecad.*) ;; *) module="freecad.hapticgrasp.$module" ;; esac
home=$(mktemp -d)
trap 'rm -rf "$home"' EXIT INT TERM
mkdir -p "$home/.local/share/FreeCAD/Mod"
ln -s "$addon" "$home/.local/share/FreeCAD/Mod/HapticGrasp"
HOME="$home" QTWEBENGINE_DISABLE_SANDBOX=1 timeout -k 10 840 \
  xvfb-run -a -s "-screen 0 1280x1024x24" "$freecad" -t "$module"
