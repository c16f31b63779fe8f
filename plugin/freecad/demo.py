"""`make demo` in the FreeCAD GUI: a document with the sample cylinder and block, the
HapticGrasp workbench active, the cylinder selected and the task panel open; press Start
(the scripted demo hand grasps the selected part, lifts it and carries it 100 mm along y).
Run: HG_RESOURCES_DIR=resources freecad plugin/freecad/demo.py (the addon installed in
~/.local/share/FreeCAD/Mod/HapticGrasp). HG_DEMO_EXIT=1 closes FreeCAD once it is set up
(a smoke test)."""
import os

import FreeCAD as App
import FreeCADGui as Gui
import Part


def _resources():
    folder = os.environ.get("HG_RESOURCES_DIR")
    if not folder:
        folder = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "resources")
    return folder


def _part(doc, name, brep, placement):
    obj = doc.addObject("Part::Feature", name)
    shape = Part.Shape()
    shape.importBrep(brep)
    obj.Shape = shape
    obj.Placement = placement
    return obj


def main():
    parts = os.path.join(_resources(), "parts")
    doc = App.newDocument("HapticGraspDemo")
    cylinder = _part(doc, "Cylinder", os.path.join(parts, "cylinder.brep"),
                     App.Placement(App.Vector(400, 0, 300), App.Rotation(App.Vector(1, 0, 0), -90)))
    _part(doc, "Block", os.path.join(parts, "block.brep"), App.Placement(App.Vector(400, 250, 300), App.Rotation()))
    doc.recompute()
    Gui.activateWorkbench("HapticGraspWorkbench")
    Gui.ActiveDocument.ActiveView.viewIsometric()
    Gui.SendMsgToActiveView("ViewFit")
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(cylinder)
    from freecad.hapticgrasp import gui as hgui
    panel = hgui._HapticGraspController.show_panel()
    App.Console.PrintMessage("HapticGrasp demo: %s; press Start in the task panel\n"
                             % ("panel open" if panel is not None else "no panel"))
    if os.environ.get("HG_DEMO_EXIT"):
        os._exit(0 if panel is not None else 1)


try:
    main()
except Exception as e:  # say why in the report view instead of failing silently
    App.Console.PrintError("HapticGrasp demo: %s\n" % e)
    if os.environ.get("HG_DEMO_EXIT"):
        os._exit(1)
