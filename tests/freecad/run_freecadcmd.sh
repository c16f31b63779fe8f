#!/bin/sh
# Runs a freecadcmd test module against the built workbench, in a throw-away HOME whose
# FreeCAD Mod folder links to the build tree's package.
#   run_freecadcmd.sh FREECADCMD PACKAGE_DIR TEST_MODULE
freecadcmd="$1"; package="$2"; module="$3"
home=$(mktemp -d)
trap 'rm -rf "$home"' EXIT INT TERM
mkdir -p "$home/.local/share/FreeCAD/Mod"
ln -s "$package" "$home/.local/share/FreeCAD/Mod/HapticGrasp"
HOME="$home" timeout -k 10 300 "$freecadcmd" -t "$module"
