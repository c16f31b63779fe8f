# HapticGrasp workbench, GUI part. FreeCAD exec()s this file inside a function: __file__
# is undefined and names defined here are not visible from methods, so the methods import
# what they need. The package is found through sys.path (FreeCAD put this Mod folder,
# .../Mod/HapticGrasp, on it) and imported as `HapticGrasp`.
import FreeCADGui as Gui


class HapticGraspWorkbench(Gui.Workbench):
    MenuText = "HapticGrasp"
    ToolTip = "Feel, grasp and move parts with a haptic device"

    def Initialize(self):
        import os
        import sys
        for entry in list(sys.path):
            folder = os.path.normpath(entry)
            if os.path.basename(folder) == "HapticGrasp" and os.path.isfile(os.path.join(folder, "session.py")):
                parent = os.path.dirname(os.path.realpath(folder))
                if parent not in sys.path:
                    sys.path.append(parent)
                break
        from HapticGrasp import gui
        commands = gui.register()
        self.appendToolbar("HapticGrasp", commands)
        self.appendMenu("HapticGrasp", commands)

    def Activated(self):
        pass

    def Deactivated(self):
        pass

    def GetClassName(self):
        return "Gui::PythonWorkbench"


Gui.addWorkbench(HapticGraspWorkbench())
