"""HapticGrasp in the real FreeCAD GUI (under Xvfb): the workbench loads, its Start
command runs the servo thread with the demo hand on the selected part, the QTimer moves
the part's Placement, the manipulation is one undo step, and the session stops itself.

Run: `QTWEBENGINE_DISABLE_SANDBOX=1 xvfb-run -a freecad -t TestHapticGraspGui` with the
built package in the Mod folder (tests/freecad/run_freecad_gui.sh)."""
import os
import sys
import time
import unittest

import FreeCAD as App
import FreeCADGui as Gui
import Part

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
from HapticGrasp import gui as hgui  # noqa: E402
from HapticGrasp import session as hs  # noqa: E402

RESOURCES = os.environ.get("HG_RESOURCES_DIR", "")


class HapticGraspGui(unittest.TestCase):
    def test_start_command_moves_the_selected_part_in_one_undo_step(self):
        from PySide2 import QtWidgets
        Gui.activateWorkbench("HapticGraspWorkbench")
        self.assertIsNotNone(Gui.Command.get("HapticGrasp_Start"))
        doc = App.newDocument("HapticGraspGui")
        doc.UndoMode = 1
        cylinder = doc.addObject("Part::Feature", "Cylinder")
        shape = Part.Shape()
        shape.importBrep(os.path.join(RESOURCES, "parts", "cylinder.brep"))
        cylinder.Shape = shape
        cylinder.Placement = App.Placement(App.Vector(400, 0, 300), App.Rotation(App.Vector(1, 0, 0), -90))
        doc.recompute()
        doc.clearUndos()
        before = App.Placement(cylinder.Placement)
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(cylinder)
        Gui.runCommand("HapticGrasp_Start")
        controller = hgui._HapticGraspController
        self.assertIsNotNone(controller.session)
        deadline = time.monotonic() + 15
        while controller.session is not None and time.monotonic() < deadline:
            QtWidgets.QApplication.processEvents()
            time.sleep(0.005)
            if controller.session is not None and controller.session.core.snapshot()["time_s"] > 2.5:
                Gui.runCommand("HapticGrasp_Stop")
        self.assertIsNone(controller.session)
        moved = cylinder.Placement.Base - before.Base
        self.assertAlmostEqual(moved.y, 100.0, delta=0.5)
        self.assertAlmostEqual(moved.z, 0.0, delta=0.5)
        self.assertEqual(doc.UndoNames, ["Haptic move Cylinder"])
        doc.undo()
        self.assertTrue(hs.same_placement(cylinder.Placement, before))
        App.closeDocument(doc.Name)
