# HapticGrasp workbench, application part (runs in freecadcmd too). __file__ is not defined
# here: nothing below may rely on it.
import FreeCAD as App

# `freecadcmd -t TestHapticGrasp` finds the test module through this list.
App.__unit_test__ += ["TestHapticGrasp"]
