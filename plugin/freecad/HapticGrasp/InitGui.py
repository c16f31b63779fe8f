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

# The preferences page "Haptic Grasp" (force parameters), available before the workbench is
# activated. Top-level statements only (see above): the package is made importable as in
# Initialize(), and a failure leaves the workbench usable.
try:
    import os as _hg_os
    import sys as _hg_sys
    for _hg_entry in list(_hg_sys.path):
        _hg_folder = _hg_os.path.normpath(_hg_entry)
        if _hg_os.path.basename(_hg_folder) == "HapticGrasp" and _hg_os.path.isfile(
                _hg_os.path.join(_hg_folder, "session.py")):
            _hg_parent = _hg_os.path.dirname(_hg_os.path.realpath(_hg_folder))
            if _hg_parent not in _hg_sys.path:
                _hg_sys.path.append(_hg_parent)
            break
    from HapticGrasp import prefs as _hg_prefs
    Gui.addPreferencePage(_hg_prefs.HapticGraspPreferences, "Haptic Grasp")
except Exception as _hg_error:
    import FreeCAD as _hg_App
    _hg_App.Console.PrintWarning("HapticGrasp: no preferences page: %s\n" % _hg_error)
