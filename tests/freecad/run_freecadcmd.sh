#!/bin/sh
# Runs a freecadcmd test module against the built workbench, in a throw-away HOME whose
# FreeCAD Mod folder links to the build tree's addon (build/freecad/HapticGrasp).
#   run_freecadcmd.sh FREECADCMD ADDON_DIR TEST_MODULE[.Class[.test]]
# The test modules are in the package freecad.hapticgrasp: a short name gets that prefix.
freecadcmd="$1"; addon="$2"; module="$3"
case "$module" in freecad.*) ;; *) module="freecad.hapticgrasp.$module" ;; esac
home=$(mktemp -d)
trap 'rm -rf "$home"' EXIT INT TERM
mkdir -p "$home/.local/share/FreeCAD/Mod"
ln -s "$addon" "$home/.local/share/FreeCAD/Mod/HapticGrasp"
HOME="$home" timeout -k 10 600 "$freecadcmd" -t "$module"
