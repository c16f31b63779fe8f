"""HapticGrasp in the real FreeCAD GUI (under Xvfb): the workbench loads, its Start
command runs the servo thread with the demo hand on the selected part, the QTimer moves
the part's Placement, the manipulation is one undo step, and the session stops itself.
While it runs the task panel is open and the Coin overlay is in the scene graph (both go
with Stop); nothing is reported as an error; a screenshot is saved to the build tree
(build/freecad/screenshots/TestHapticGraspGui.png). Sounds are requested on transitions and
stay silent without an audio server. Frame rates are never asserted.

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
SCREENSHOT = os.path.join(os.path.dirname(os.path.dirname(os.path.realpath(__file__))), "screenshots",
                          "TestHapticGraspGui.png")


class _ErrorLog:
    """Records App.Console.PrintError calls and uncaught exceptions (Qt slots) meanwhile."""

    def __enter__(self):
        self.errors = []
        self._print_error = App.Console.PrintError
        self._excepthook = sys.excepthook

        def print_error(text, *args):
            self.errors.append(str(text))
            return self._print_error(text, *args)

        def excepthook(kind, value, tb):
            self.errors.append("%s: %s" % (kind.__name__, value))
            return self._excepthook(kind, value, tb)

        App.Console.PrintError = print_error
        sys.excepthook = excepthook
        return self

    def __exit__(self, *exc):
        App.Console.PrintError = self._print_error
        sys.excepthook = self._excepthook
        return False


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
        Gui.ActiveDocument.ActiveView.viewIsometric()
        Gui.SendMsgToActiveView("ViewFit")
        controller = hgui._HapticGraspController
        seen = {"overlay": False, "panel": False, "screenshot": False, "states": set()}
        with _ErrorLog() as log:
            Gui.runCommand("HapticGrasp_Start")
            self.assertIsNotNone(controller.session)
            Gui.Selection.clearSelection()   # an unhighlighted part in the screenshot
            deadline = time.monotonic() + 15
            while controller.session is not None and time.monotonic() < deadline:
                QtWidgets.QApplication.processEvents()
                time.sleep(0.005)
                if controller.session is None:
                    break
                seen["states"].add(controller.session.state)
                overlay = controller.overlay
                graph = Gui.ActiveDocument.ActiveView.getSceneGraph()
                if overlay is not None and graph.findChild(overlay.root) >= 0:
                    seen["overlay"] = True
                panel = controller.panel
                if panel is not None and Gui.Control.activeDialog() and panel.form.findChild(
                        QtWidgets.QLabel, "HapticGrasp_state") is not None:
                    seen["panel"] = True
                if not seen["screenshot"] and controller.session.state == "MANIPULATE":
                    os.makedirs(os.path.dirname(SCREENSHOT), exist_ok=True)
                    Gui.ActiveDocument.ActiveView.saveImage(SCREENSHOT, 640, 480)
                    seen["screenshot"] = True
                    fields = controller.panel.fields
                    seen["panel_state"] = fields["state"].text()
                    seen["panel_part"] = fields["part"].text()
                    controller.panel.form.grab().save(SCREENSHOT.replace(".png", "_panel.png"))
                if controller.session.core.snapshot()["time_s"] > 2.5:
                    Gui.runCommand("HapticGrasp_Stop")
            self.assertIsNone(controller.session)
            QtWidgets.QApplication.processEvents()
        self.assertEqual(log.errors, [])
        self.assertTrue(seen["overlay"], "the overlay was never in the scene graph")
        self.assertTrue(seen["panel"], "the task panel was never shown")
        self.assertIn("MANIPULATE", seen["states"])
        self.assertEqual(seen.get("panel_state"), "MANIPULATE")
        self.assertEqual(seen.get("panel_part"), "Cylinder")
        self.assertTrue(seen["screenshot"] and os.path.getsize(SCREENSHOT) > 0)
        # Stop removed the overlay; the panel stays open (Start again), Close shuts it.
        self.assertIsNone(controller.overlay)
        self.assertEqual(self._overlay_nodes(), 0)
        self.assertIsNotNone(controller.panel)
        self.assertFalse(controller.panel.stop_button.isEnabled())
        controller.panel.reject()
        QtWidgets.QApplication.processEvents()
        self.assertIsNone(controller.panel)
        self.assertFalse(Gui.Control.activeDialog())
        # Sounds: requested on the transitions, played only where an audio output exists.
        self.assertIn("lift", controller.sounds.requested)
        self.assertTrue(set(controller.sounds.played) <= set(controller.sounds.requested))
        App.Console.PrintMessage("HapticGrasp GUI test: sounds %s, screenshot %s\n"
                                 % (controller.sounds.status(), SCREENSHOT))
        moved = cylinder.Placement.Base - before.Base
        self.assertAlmostEqual(moved.y, 100.0, delta=0.5)
        self.assertAlmostEqual(moved.z, 0.0, delta=0.5)
        self.assertEqual(doc.UndoNames, ["Haptic move Cylinder"])
        doc.undo()
        self.assertTrue(hs.same_placement(cylinder.Placement, before))
        App.closeDocument(doc.Name)

    def test_start_builds_the_models_with_a_progress_bar_and_cancel(self):
        from PySide2 import QtWidgets
        Gui.activateWorkbench("HapticGraspWorkbench")
        doc = App.newDocument("HapticGraspBuild")
        for i in range(5):
            block = doc.addObject("Part::Feature", "Block%d" % i)
            shape = Part.Shape()
            shape.importBrep(os.path.join(RESOURCES, "parts", "block.brep"))
            block.Shape = shape
            block.Placement = App.Placement(App.Vector(0, 400 * i, 0), App.Rotation())
        doc.recompute()
        controller = hgui._HapticGraspController
        seen = {"ticks": 0, "values": [], "labels": set()}

        def count():
            seen["ticks"] += 1

        with _ErrorLog() as log:
            Gui.runCommand("HapticGrasp_Start")
            session, panel = controller.session, controller.panel
            self.assertIsNotNone(session)
            self.assertFalse(session.ready)
            self.assertIsNotNone(panel)
            controller.timer.timeout.connect(count)
            self.assertFalse(panel.build_bar.isHidden())
            self.assertFalse(panel.start_button.isEnabled())
            self.assertTrue(panel.cancel_button.isEnabled())
            deadline = time.monotonic() + 120
            while panel.build_bar.value() < 2 and time.monotonic() < deadline:
                QtWidgets.QApplication.processEvents()   # the GUI thread stays free
                seen["labels"].add(panel.build_label.text())
                if not seen["values"] or seen["values"][-1] != panel.build_bar.value():
                    seen["values"].append(panel.build_bar.value())
                time.sleep(0.005)
            self.assertFalse(session.ready)
            panel.cancel_button.click()
            QtWidgets.QApplication.processEvents()
            self.assertIsNone(controller.session)
            self.assertIsNone(controller.timer)
            self.assertTrue(session.cancelled)
            self.assertEqual(session.core.part_count(), 0)
            self.assertTrue(panel.build_bar.isHidden())
            self.assertTrue(panel.start_button.isEnabled())
            while hs.drain() and time.monotonic() < deadline:   # the worker ends its part
                QtWidgets.QApplication.processEvents()
                time.sleep(0.01)
        App.Console.PrintMessage("HapticGrasp GUI build: %d timer ticks while building, bar %s, labels %s\n"
                                 % (seen["ticks"], seen["values"], sorted(seen["labels"])))
        self.assertEqual(log.errors, [])
        self.assertGreaterEqual(seen["ticks"], 5)    # the QTimer kept ticking during the build
        self.assertEqual(seen["values"][0], 0)
        self.assertGreaterEqual(seen["values"][-1], 2)
        self.assertTrue(any(label.startswith("Building Block") for label in seen["labels"]), seen["labels"])
        panel.reject()
        QtWidgets.QApplication.processEvents()
        App.closeDocument(doc.Name)

    def test_mark_graspable_command_toggles_the_selection_in_one_undo_step(self):
        Gui.activateWorkbench("HapticGraspWorkbench")
        doc = App.newDocument("HapticGraspMark")
        doc.UndoMode = 1
        a = doc.addObject("Part::Box", "A")
        b = doc.addObject("Part::Box", "B")
        b.Placement.Base = App.Vector(50, 0, 0)
        doc.recompute()
        doc.clearUndos()
        try:
            Gui.Selection.clearSelection()
            Gui.Selection.addSelection(a)
            Gui.runCommand("HapticGrasp_MarkGraspable")
            self.assertTrue(hs.is_graspable(a))
            self.assertFalse(hs.is_graspable(b))
            self.assertEqual([o.Name for o in hs.collect_solids(doc, [])], ["A"])
            self.assertEqual(doc.UndoNames, ["Mark graspable"])
            Gui.runCommand("HapticGrasp_MarkGraspable")   # all selected marked: unmark
            self.assertFalse(hs.is_graspable(a))
            self.assertEqual([o.Name for o in hs.collect_solids(doc, [])], ["A", "B"])
        finally:
            Gui.Selection.clearSelection()
            App.closeDocument(doc.Name)

    def test_transition_sounds(self):
        from HapticGrasp import sounds as hsounds
        steps = ["FREE", "INDEX CONTACT", "THUMB CONTACT", "GRASP", "MANIPULATE", "GRASP", "FREE"]
        played = [hsounds.transition_sound(a, b) for a, b in zip(steps, steps[1:])]
        self.assertEqual(played, ["contact", None, "grasp", "lift", None, "release"])
        self.assertEqual(hsounds.transition_sound("GRASP", "GRASP", fault=True), "fault")
        board = hsounds.SoundBoard()
        self.assertEqual(sorted(board.effects), sorted(hsounds.NAMES))
        board.play("grasp")      # silent without an audio server, never raises
        self.assertEqual(board.requested, ["grasp"])
        board.close()

    def test_the_preferences_page_stores_the_force_parameters(self):
        from HapticGrasp import prefs as hprefs
        group = App.ParamGet(hs.PARAMETER_PATH)
        page = hprefs.HapticGraspPreferences()
        try:
            self.assertEqual(page.form.windowTitle(), "Haptic Grasp")
            page.loadSettings()
            shown = {key: spin.value() for key, spin in page.spins.items()}
            self.assertEqual(shown, hs.default_parameters())
            self.assertEqual(shown["K_g"], 1000.0)
            page.spins["K_g"].setValue(1500.0)
            page.spins["d_h"].setValue(0.003)
            page.saveSettings()
            self.assertEqual(group.GetFloat("K_g"), 1500.0)
            self.assertEqual(hs.stored_parameters()["d_h"], 0.003)
            page.reset()
            self.assertEqual(page.spins["K_g"].value(), 1000.0)
        finally:
            for key in hs.PARAMETER_KEYS:
                group.RemFloat(key)
            page.form.deleteLater()

    def test_the_panel_offers_a_device_choice_with_the_mouse(self):
        from PySide2 import QtWidgets
        Gui.activateWorkbench("HapticGraspWorkbench")
        controller = hgui._HapticGraspController
        panel = controller.show_panel()
        self.assertIsNotNone(panel)
        try:
            combo = panel.form.findChild(QtWidgets.QComboBox, "HapticGrasp_DeviceCombo")
            self.assertIsNotNone(combo)
            titles = [combo.itemText(i) for i in range(combo.count())]
            self.assertIn("Demo script", titles)
            self.assertIn("Mouse and keyboard", titles)
            mouse = combo.findData("mouse")
            self.assertTrue(combo.model().item(mouse).isEnabled())
            combo.setCurrentIndex(mouse)
            self.assertEqual(controller.device, "mouse")
        finally:
            controller.device = "demo"
            panel.reject()
            QtWidgets.QApplication.processEvents()

    @staticmethod
    def _overlay_nodes():
        from pivy import coin
        search = coin.SoSearchAction()
        search.setName(coin.SbName("HapticGraspOverlay"))
        search.setInterest(coin.SoSearchAction.ALL)
        search.apply(Gui.ActiveDocument.ActiveView.getSceneGraph())
        return search.getPaths().getLength()
