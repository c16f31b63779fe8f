"""HapticGrasp, GUI part: FreeCAD imports `freecad.hapticgrasp.init_gui` once the GUI is up
(FreeCADGuiInit.py, for every package in the `freecad` namespace). A real module, unlike a
legacy InitGui.py: __file__ is defined and the workbench's methods see these imports."""
import FreeCAD as App
import FreeCADGui as Gui

from freecad import hapticgrasp


# The translations (resources/translations/HapticGrasp_<language>.qm, from the template
# HapticGrasp.ts) are loaded for FreeCAD's language, as FreeCAD's addons do: before anything
# below is translated.
Gui.addLanguagePath(hapticgrasp.TRANSLATIONS_DIR)
Gui.updateLocale()


class HapticGraspWorkbench(Gui.Workbench):
    MenuText = "HapticGrasp"   # the name, not translated
    ToolTip = App.Qt.translate("HapticGrasp", "Feel, grasp and move parts with a haptic device")
    Icon = hapticgrasp.icon("HapticGraspWorkbench.svg")

    def Initialize(self):
        from freecad.hapticgrasp import gui
        commands = gui.register()
        self.appendToolbar("HapticGrasp", commands)
        self.appendMenu("HapticGrasp", commands)

    def Activated(self):
        pass

    def Deactivated(self):
        pass

    def GetClassName(self):
        return "Gui::PythonWorkbench"


def _add_preferences_page():
    """The preferences page "Haptic Grasp" (force parameters), available before the
    workbench is activated; a failure leaves the workbench usable. Its group's icon is
    looked up by name (preferences-haptic_grasp.svg) in the icon paths."""
    Gui.addIconPath(hapticgrasp.ICON_DIR)
    try:
        from freecad.hapticgrasp import prefs
        Gui.addPreferencePage(prefs.HapticGraspPreferences, "Haptic Grasp")
    except Exception as e:
        App.Console.PrintWarning("HapticGrasp: no preferences page: %s\n" % e)


Gui.addWorkbench(HapticGraspWorkbench())
_add_preferences_page()
