"""HapticGrasp, application part: FreeCAD imports `freecad.hapticgrasp.init` at start-up,
in freecadcmd too (FreeCADInit.py imports `<package>.init` of every package it finds in the
`freecad` namespace; no Init.py is exec'd for a namespace addon)."""
import FreeCAD as App

# The Test workbench and `freecadcmd -t 0` run every module in this list (unittest names:
# dotted names load as they do with `freecadcmd -t freecad.hapticgrasp.TestHapticGrasp`).
App.__unit_test__ += ["freecad.hapticgrasp.TestHapticGrasp"]
