"""HapticGrasp in the real FreeCAD GUI (under Xvfb): the workbench loads, its Start
command runs the servo thread with the demo hand on the selected part, the QTimer moves
the part's Placement, the manipulation is one undo step, and the session stops itself.
While it runs the task panel is open and the Coin overlay is in the scene graph (both go
with Stop); nothing is reported as an error; a screenshot is saved to the build tree
(build/freecad/screenshots/TestHapticGraspGui.png). Sounds are requested on transitions and
stay silent without an audio server. Frame rates are never asserted.

Run: `QTWEBENGINE_DISABLE_SANDBOX=1 xvfb-run -a freecad -t freecad.hapticgrasp.TestHapticGraspGui`
with the built addon in the Mod folder (tests/freecad/run_freecad_gui.sh)."""
import os
import sys
import time
import unittest

import FreeCAD as App
import FreeCADGui as Gui
import Part

from freecad.hapticgrasp import gui as hgui
from freecad.hapticgrasp import session as hs

RESOURCES = os.environ.get("HG_RESOURCES_DIR", "")
# build/freecad/screenshots: this file is build/freecad/HapticGrasp/freecad/hapticgrasp/<this>.
SCREENSHOT_DIR = os.path.normpath(os.path.join(os.path.dirname(os.path.realpath(__file__)), os.pardir, os.pardir,
                                               os.pardir, "screenshots"))
SCREENSHOT = os.path.join(SCREENSHOT_DIR, "TestHapticGraspGui.png")


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


def click_task_close(test):
    """Clicks the task view's Close button (the open task dialog's), as the user does."""
    from PySide2 import QtWidgets
    close = None
    for box in Gui.getMainWindow().findChildren(QtWidgets.QDialogButtonBox):
        button = box.button(QtWidgets.QDialogButtonBox.Close)
        if button is not None and button.isVisible():
            close = button
    test.assertIsNotNone(close, "no Close button in the task view")
    close.click()


def cylinder_doc(name, save_in=None):
    """A new document (undo on) holding the sample cylinder lying along y at (400, 0, 300)
    mm, seen from the front (right = +x, up = +z, into the screen = +y); saved in the folder
    save_in when given. No undo entry."""
    doc = App.newDocument(name)
    doc.UndoMode = 1
    cylinder = doc.addObject("Part::Feature", "Cylinder")
    shape = Part.Shape()
    shape.importBrep(os.path.join(RESOURCES, "parts", "cylinder.brep"))
    cylinder.Shape = shape
    cylinder.Placement = App.Placement(App.Vector(400, 0, 300), App.Rotation(App.Vector(1, 0, 0), -90))
    doc.recompute()
    if save_in:
        doc.saveAs(os.path.join(save_in, name + ".FCStd"))
    doc.clearUndos()
    Gui.ActiveDocument.ActiveView.viewFront()
    Gui.SendMsgToActiveView("ViewFit")
    return doc, cylinder


class HapticGraspGui(unittest.TestCase):
    def test_closing_the_document_mid_move_stops_haptics_without_an_error(self):
        """Issue 14: the document closed while the servo runs and a part is held: the timer
        stops haptics (overlay and event filter removed from a view that is gone), nothing
        is raised or printed as an error, and FreeCAD goes on."""
        from PySide2 import QtWidgets
        Gui.activateWorkbench("HapticGraspWorkbench")
        doc, cylinder = self._cylinder_doc("HapticGraspClosed")
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(cylinder)
        controller = hgui._HapticGraspController
        with _ErrorLog() as log:
            Gui.runCommand("HapticGrasp_Start")
            deadline = time.monotonic() + 15
            while controller.session is not None and controller.session.state != "MANIPULATE":
                self.assertLess(time.monotonic(), deadline, "never lifted")
                QtWidgets.QApplication.processEvents()
                time.sleep(0.005)
            session = controller.session
            self.assertIsNotNone(session)
            App.closeDocument(doc.Name)
            deadline = time.monotonic() + 2
            while controller.session is not None and time.monotonic() < deadline:
                QtWidgets.QApplication.processEvents()
                time.sleep(0.005)
            self.assertIsNone(controller.session)
            self.assertFalse(session.running)
            self.assertIn("the document was closed: haptics stopped", session.messages)
            if Gui.Control.activeDialog():
                click_task_close(self)   # the panel stays, saying so, until the user closes it
            QtWidgets.QApplication.processEvents()
            self.assertIsNone(controller.panel)
        self.assertEqual([e for e in log.errors if "document was closed" not in e], [])
        other, _ = self._cylinder_doc("HapticGraspAfterClose")   # FreeCAD goes on
        App.closeDocument(other.Name)

    def test_switching_workbench_mid_session_keeps_haptics_running_until_stop(self):
        """Issue 14: another workbench activated while the servo runs: haptics go on (the
        controller belongs to no workbench) and Stop still ends them cleanly."""
        from PySide2 import QtWidgets
        Gui.activateWorkbench("HapticGraspWorkbench")
        doc, cylinder = self._cylinder_doc("HapticGraspSwitch")
        Gui.Selection.addSelection(cylinder)
        controller = hgui._HapticGraspController
        with _ErrorLog() as log:
            Gui.runCommand("HapticGrasp_Start")
            deadline = time.monotonic() + 15
            while controller.session is None or not controller.session.running:
                self.assertLess(time.monotonic(), deadline, "never started")
                QtWidgets.QApplication.processEvents()
                time.sleep(0.005)
            Gui.activateWorkbench("PartWorkbench")
            ticks = controller.session.core.snapshot()["tick"]
            end = time.monotonic() + 0.5
            while time.monotonic() < end:
                QtWidgets.QApplication.processEvents()
                time.sleep(0.005)
            self.assertTrue(controller.session.running)
            # Still ticking (1,000 ticks in 0.5 s at 2 kHz; a stopped servo adds none, and a
            # held VM may take a few hundred).
            self.assertGreater(controller.session.core.snapshot()["tick"], ticks + 100)
            Gui.runCommand("HapticGrasp_Stop")
            QtWidgets.QApplication.processEvents()
            self.assertIsNone(controller.session)
            if Gui.Control.activeDialog():
                click_task_close(self)
            QtWidgets.QApplication.processEvents()
        self.assertEqual(log.errors, [])
        Gui.activateWorkbench("HapticGraspWorkbench")
        App.closeDocument(doc.Name)

    def test_start_command_moves_the_selected_part_in_one_undo_step(self):
        from PySide2 import QtWidgets
        Gui.activateWorkbench("HapticGraspWorkbench")
        self.assertIsNotNone(Gui.Command.get("HapticGrasp_Start"))
        doc, cylinder = self._cylinder_doc("HapticGraspGui")
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
                    seen["timing"] = controller.session.servo_timing()   # the real workbench's servo
                    seen["realtime_text"] = controller.panel.fields["realtime"].text()
                    Gui.runCommand("HapticGrasp_Stop")
            self.assertIsNone(controller.session)
            QtWidgets.QApplication.processEvents()
        self.assertEqual(log.errors, [])
        self._write_servo_timing(seen["timing"], seen["realtime_text"])
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

    def _write_servo_timing(self, timing, panel_text):
        """The workbench's own servo timing under Xvfb and the software renderer, to
        build/freecad/gui-servo-timing.json (README's figure next to the benchmark's): at
        least half the 2 kHz default when SCHED_FIFO was granted (the figure itself is
        the README's), and the panel says what the thread got."""
        import json
        figures = {"target_hz": timing["target_hz"], "achieved_hz": timing["achieved_hz"],
                   "period_err_us": timing["period_err_us"], "scheduler": timing["scheduler"],
                   "memory_lock": timing["memory_lock"], "ticks": timing["ticks"]}
        with open(os.path.join(os.path.dirname(SCREENSHOT_DIR), "gui-servo-timing.json"), "w") as f:
            json.dump(figures, f, indent=2)
        App.Console.PrintMessage("HapticGrasp GUI servo: %s\n" % json.dumps(figures))
        self.assertEqual(timing["target_hz"], 2000.0)
        if timing["scheduler"] == "SCHED_FIFO":
            # The figure goes to README; asserted is only that the thread ran at its rate,
            # not at a GUI timer's (a loaded CI machine may hold it for a while).
            self.assertGreaterEqual(timing["achieved_hz"], 0.5 * 2000.0, figures)
            self.assertTrue(panel_text.startswith("SCHED_FIFO"), panel_text)
        else:
            self.assertTrue(timing["advice"], timing)
            self.assertTrue(panel_text.startswith("refused"), panel_text)

    def test_start_runs_the_servo_at_once_and_builds_the_models_behind_it(self):
        from PySide2 import QtWidgets
        Gui.activateWorkbench("HapticGraspWorkbench")
        doc = App.newDocument("HapticGraspBuild")
        for i in range(5):   # the 1,030-face plate: builds long enough to watch the GUI meanwhile
            plate = doc.addObject("Part::Feature", "Plate%d" % i)
            shape = Part.Shape()
            shape.importBrep(os.path.join(RESOURCES, "parts", "plate.brep"))
            plate.Shape = shape
            plate.Placement = App.Placement(App.Vector(0, 400 * i, 0), App.Rotation())
        doc.recompute()
        controller = hgui._HapticGraspController
        seen = {"ticks": 0, "exact": []}

        def count():
            seen["ticks"] += 1

        with _ErrorLog() as log:
            began = time.monotonic()
            Gui.runCommand("HapticGrasp_Start")
            started_s = time.monotonic() - began
            session, panel = controller.session, controller.panel
            self.assertIsNotNone(session)
            self.assertTrue(session.running)     # the servo runs before any model is built
            self.assertIsNotNone(panel)
            self.assertFalse(panel.start_button.isEnabled())
            self.assertTrue(panel.stop_button.isEnabled())
            controller.timer.timeout.connect(count)
            # The builders run at SCHED_BATCH, nice 19: on this 2-core machine with a
            # software renderer and another test beside this one they get the leftovers
            # (measured at SCHED_IDLE: 56-70 s alone, 68-72 s beside the freecadcmd tests,
            # 66 s to over 300 s while they were kept on the GUI thread's CPU; 83 s at nice
            # 19 beside a nice-19 fuzzer, 128 s at SCHED_IDLE: scene_build.cpp; loaded in the
            # loader process, 98-99 s beside a fuzzer or the freecadcmd and package tests, and
            # 224 s beside the whole unit suite at -j2 and a fuzzer). Time is not what this
            # test asserts; the deadline only stops a build that never ends (ctest: 900 s).
            deadline = began + 600
            loop_times = [time.monotonic()]
            gui_cpu = time.thread_time()   # this (the GUI) thread's CPU time
            while time.monotonic() < deadline:
                QtWidgets.QApplication.processEvents()   # the GUI thread stays free
                loop_times.append(time.monotonic())
                exact = session.scene_progress()[0]
                if not seen["exact"] or seen["exact"][-1] != exact:
                    seen["exact"].append(exact)
                if exact == 5:
                    break
                time.sleep(0.005)
            building_s = loop_times[-1] - loop_times[0]
            gui_cpu = time.thread_time() - gui_cpu
            # The panel refreshes on the controller's timer from the servo's snapshot, which
            # follows the last swap a tick later: one processEvents() may come before either.
            settle = time.monotonic() + 5
            while (panel.fields["models"].text() != "5 of 5 parts" and time.monotonic() < settle):
                QtWidgets.QApplication.processEvents()
                time.sleep(0.005)
            models_text = panel.fields["models"].text()
            self.assertTrue(session.running)
            panel.stop_button.click()
            QtWidgets.QApplication.processEvents()
            self.assertIsNone(controller.session)
        longest_stall = max(b - a for a, b in zip(loop_times, loop_times[1:]))
        App.Console.PrintMessage("HapticGrasp GUI scene: servo running %.3f s after Start; %d timer ticks in %.3f s "
                                 "of building, the GUI thread busy %.0f%% of it, longest stall %.3f s, exact parts %s, "
                                 "panel '%s'\n" % (started_s, seen["ticks"], building_s, 100 * gui_cpu / building_s,
                                                    longest_stall, seen["exact"], models_text))
        self.assertEqual(log.errors, [])
        self.assertEqual(seen["exact"][0], 0)
        self.assertEqual(seen["exact"][-1], 5)
        self.assertEqual(models_text, "5 of 5 parts")
        self.assertTrue(any("Plate" in line for line in session.part_reports), session.part_reports)
        # The QTimer (20 ms) kept ticking while the models were built, however long that took
        # on this machine; a quarter of the ticks leaves room for a busy machine.
        self.assertGreaterEqual(seen["ticks"], max(1, int(building_s / 0.020 / 4)))
        # Built off the GUI thread: a plate's model and contact shell built on it would hold
        # it for seconds (8.8 s alone); measured 0.13-0.47 s here, beside another test.
        self.assertLess(longest_stall, 2.0)
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
            self.assertEqual([r.obj.Name for r in hs.collect_solids(doc, [])], ["A"])
            self.assertEqual(doc.UndoNames, ["Mark graspable"])
            Gui.runCommand("HapticGrasp_MarkGraspable")   # all selected marked: unmark
            self.assertFalse(hs.is_graspable(a))
            self.assertEqual([r.obj.Name for r in hs.collect_solids(doc, [])], ["A", "B"])
        finally:
            Gui.Selection.clearSelection()
            App.closeDocument(doc.Name)

    def test_transition_sounds(self):
        from freecad.hapticgrasp import sounds as hsounds
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
        from freecad.hapticgrasp import prefs as hprefs
        group = App.ParamGet(hs.PARAMETER_PATH)
        page = hprefs.HapticGraspPreferences()
        try:
            self.assertEqual(page.form.windowTitle(), "Haptic Grasp")
            page.loadSettings()
            shown = {key: spin.value() for key, spin in page.spins.items()}
            self.assertEqual(shown, hs.default_parameters())
            self.assertEqual(shown["K_g"], 1000.0)
            self.assertEqual(page.method.currentData(), "two-finger")
            page.spins["K_g"].setValue(1500.0)
            page.spins["d_h"].setValue(0.003)
            page.spins["k"].setValue(1200.0)   # the multi-finger method's, on the same page
            page.method.setCurrentIndex(page.method.findData("multi-finger"))
            page.saveSettings()
            self.assertEqual(group.GetFloat("K_g"), 1500.0)
            self.assertEqual(hs.stored_parameters()["d_h"], 0.003)
            self.assertEqual(group.GetFloat("k"), 1200.0)
            self.assertEqual(hs.stored_method(), "multi-finger")
            page.reset()
            self.assertEqual(page.spins["K_g"].value(), 1000.0)
            self.assertEqual(page.method.currentData(), "two-finger")
        finally:
            for key in hs.PARAMETER_KEYS:
                group.RemFloat(key)
            group.RemString(hs.METHOD_KEY)
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

    # --- the mouse hand through the live Qt -> Coin event path ---------------------------
    def _cylinder_doc(self, name):
        return cylinder_doc(name)

    def _start_mouse_hand(self):
        from PySide2 import QtWidgets
        Gui.activateWorkbench("HapticGraspWorkbench")
        controller = hgui._HapticGraspController
        controller.device = "mouse"
        self._start_and_build()
        self.assertIsNotNone(controller.session)
        self.assertIsNotNone(controller.events)
        self._wait(0.2)
        QtWidgets.QApplication.processEvents()
        return controller

    def _start_and_build(self, timeout_s=120):
        """The Start command, then the GUI's events until the models are built and the
        device is chosen (Start builds them on a worker while the timer keeps ticking)."""
        from PySide2 import QtWidgets
        controller = hgui._HapticGraspController
        Gui.runCommand("HapticGrasp_Start")
        deadline = time.monotonic() + timeout_s
        while controller.session is not None and not controller.session.ready and time.monotonic() < deadline:
            QtWidgets.QApplication.processEvents()
            time.sleep(0.005)

    @staticmethod
    def _wait(seconds):
        from PySide2 import QtWidgets
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            QtWidgets.QApplication.processEvents()
            time.sleep(0.005)

    @staticmethod
    def _widgets():
        """The 3D view's QGraphicsView (key events) and its viewport (mouse and wheel)."""
        view = Gui.ActiveDocument.ActiveView.graphicsView()
        return view, view.viewport()

    def _move_mouse(self, x, y):
        from PySide2 import QtCore, QtGui, QtWidgets
        _, viewport = self._widgets()
        event = QtGui.QMouseEvent(QtCore.QEvent.MouseMove, QtCore.QPointF(x, y), QtCore.Qt.NoButton,
                                  QtCore.Qt.NoButton, QtCore.Qt.NoModifier)
        QtWidgets.QApplication.sendEvent(viewport, event)

    def _wheel(self, notches, x, y):
        from PySide2 import QtCore, QtGui, QtWidgets
        _, viewport = self._widgets()
        event = QtGui.QWheelEvent(QtCore.QPointF(x, y), QtCore.QPointF(viewport.mapToGlobal(QtCore.QPoint(x, y))),
                                  QtCore.QPoint(0, 0), QtCore.QPoint(0, 120 * notches), QtCore.Qt.NoButton,
                                  QtCore.Qt.NoModifier, QtCore.Qt.NoScrollPhase, False)
        QtWidgets.QApplication.sendEvent(viewport, event)

    def _key(self, key, press):
        from PySide2 import QtCore, QtGui, QtWidgets
        view, _ = self._widgets()
        kind = QtCore.QEvent.KeyPress if press else QtCore.QEvent.KeyRelease
        text = {QtCore.Qt.Key_G: "g", QtCore.Qt.Key_Escape: "\x1b"}.get(key, "")
        QtWidgets.QApplication.sendEvent(view, QtGui.QKeyEvent(kind, key, QtCore.Qt.NoModifier, text))

    @staticmethod
    def _mm_per_px(x, y):
        view = Gui.ActiveDocument.ActiveView
        return (view.getPoint(x + 1, y) - view.getPoint(x, y)).Length

    @staticmethod
    def _snapshot_hand(controller):
        index, thumb, wrist = (App.Vector(*p) for p in controller.session.core.snapshot()["hand"])
        return (index + thumb) * 0.5, (index - thumb).Length

    def test_mouse_wheel_and_key_events_on_the_3d_view_move_the_hand(self):
        from PySide2 import QtCore
        doc, cylinder = self._cylinder_doc("HapticGraspMouseEvents")
        controller = None
        with _ErrorLog() as log:
            try:
                controller = self._start_mouse_hand()
                x, y = 300, 300
                scale = self._mm_per_px(x, y)
                self.assertGreater(scale, 0)
                # View plane: 40 px right and 20 px up (Qt's y points down).
                self._move_mouse(x, y)
                self._wait(0.1)
                centre0, grip0 = self._snapshot_hand(controller)
                self._move_mouse(x + 40, y - 20)
                self._wait(0.3)
                centre1, grip1 = self._snapshot_hand(controller)
                moved = centre1 - centre0
                # Coin sees device pixels (Qt's logical pixels times the device pixel ratio,
                # 1.04 under this Xvfb): the hand follows the cursor's point on the focal
                # plane, to within the one pixel Coin's integer positions round off.
                # (getPoint takes device pixels from the bottom left, as Coin does.)
                dpr = self._widgets()[1].devicePixelRatioF()
                view = Gui.ActiveDocument.ActiveView
                height = view.getSize()[1]

                def focal(qx, qy):
                    return view.getPoint(int(round(qx * dpr)), height - int(round(qy * dpr)))

                expected = focal(x + 40, y - 20) - focal(x, y)
                print("mouse events: %.4f mm/px, device pixel ratio %.3f, hand moved (%.3f, %.3f, %.3f) mm, "
                      "the cursor's point (%.3f, %.3f, %.3f) mm"
                      % (scale, dpr, moved.x, moved.y, moved.z, expected.x, expected.y, expected.z))
                self.assertGreater(moved.x, 0)                              # right = +x
                self.assertGreater(moved.z, 0)                              # up = +z
                self.assertAlmostEqual(moved.x, expected.x, delta=1.01 * scale)
                self.assertAlmostEqual(moved.z, expected.z, delta=1.01 * scale)
                self.assertAlmostEqual(moved.y, 0.0, delta=1e-6)            # in the view plane
                # Depth: one wheel notch away from the user pushes the hand 10 mm into the screen.
                camera = Gui.ActiveDocument.ActiveView.getCamera()
                self._wheel(1, x + 40, y - 20)
                self._wait(0.3)
                self.assertEqual(Gui.ActiveDocument.ActiveView.getCamera(), camera)   # no zoom
                centre2, _ = self._snapshot_hand(controller)
                depth = centre2 - centre1
                self.assertAlmostEqual(depth.y, hgui.MouseEvents.MM_PER_WHEEL_STEP, delta=1e-6)
                self.assertAlmostEqual(depth.x, 0.0, delta=1e-6)
                self.assertAlmostEqual(depth.z, 0.0, delta=1e-6)
                # Pinch: G held closes the grip, released opens it again.
                self._key(QtCore.Qt.Key_G, True)
                self._wait(0.5)
                _, pinched = self._snapshot_hand(controller)
                self._key(QtCore.Qt.Key_G, False)
                self._wait(0.5)
                _, reopened = self._snapshot_hand(controller)
                print("pinch: grip %.1f -> %.1f -> %.1f mm" % (grip1, pinched, reopened))
                self.assertLess(pinched, grip1 - 5.0)
                self.assertGreater(reopened, pinched + 5.0)
                self.assertEqual(controller.session.fault, "none")
            finally:
                if controller is not None:
                    controller.stop()
                    if controller.panel is not None:
                        controller.panel.reject()
                    controller.device = "demo"
                self._wait(0.1)
        self.assertEqual(log.errors, [])
        self.assertEqual(doc.UndoCount, 0)
        App.closeDocument(doc.Name)

    def test_the_simulated_arm_follows_the_mouse_target_from_real_events(self):
        from PySide2 import QtWidgets
        doc = App.newDocument("HapticGraspArmEvents")
        doc.UndoMode = 1
        block = doc.addObject("Part::Feature", "Block")
        shape = Part.Shape()
        shape.importBrep(os.path.join(RESOURCES, "parts", "block.brep"))
        block.Shape = shape
        doc.recompute()
        doc.clearUndos()
        Gui.ActiveDocument.ActiveView.viewFront()   # right = +x, up = +z
        Gui.SendMsgToActiveView("ViewFit")
        controller = hgui._HapticGraspController
        with _ErrorLog() as log:
            try:
                Gui.activateWorkbench("HapticGraspWorkbench")
                panel = controller.show_panel()
                combo = panel.form.findChild(QtWidgets.QComboBox, "HapticGrasp_DeviceCombo")
                arm = combo.findData("arm")
                self.assertGreaterEqual(arm, 0)
                self.assertEqual(combo.itemText(arm), "Simulated arm")
                self.assertTrue(combo.model().item(arm).isEnabled())
                combo.setCurrentIndex(arm)
                self.assertEqual(controller.device, "arm")
                self._start_and_build()
                self.assertIsNotNone(controller.events)
                session = controller.session
                self.assertEqual(session.core.device_name, "simulated arm")
                self._wait(0.8)   # the arm settles on its first target
                overlay = controller.overlay
                self.assertIsNotNone(overlay)
                from pivy import coin
                self.assertEqual(overlay.target_switch.whichChild.getValue(), coin.SO_SWITCH_ALL)
                x, y = 300, 300
                self._move_mouse(x, y)
                self._wait(0.1)
                target0 = (session.target[0] + session.target[1]) * 0.5
                arm0, _ = self._snapshot_hand(controller)
                px = max(1, int(round(20.0 / self._mm_per_px(x, y))))   # about 20 mm to the right
                for i in range(1, 11):
                    self._move_mouse(x + px * i // 10, y)
                    self._wait(0.03)
                self._wait(1.0)
                target1 = (session.target[0] + session.target[1]) * 0.5
                arm1, _ = self._snapshot_hand(controller)
                wanted, got = target1 - target0, arm1 - arm0
                print("arm from real events: target moved (%.1f, %.1f, %.1f) mm, the arm's grip centre "
                      "(%.1f, %.1f, %.1f) mm" % (wanted.x, wanted.y, wanted.z, got.x, got.y, got.z))
                self.assertGreater(wanted.x, 10.0)
                self.assertAlmostEqual(got.x, wanted.x, delta=0.25 * wanted.x)   # the arm follows, its own way
                self.assertEqual(session.fault, "none")
            finally:
                controller.stop()
                if controller.panel is not None:
                    controller.panel.reject()
                controller.device = "demo"
                self._wait(0.1)
        self.assertEqual(log.errors, [])
        self.assertEqual(doc.UndoCount, 0)
        App.closeDocument(doc.Name)

    def _grasp_and_lift_with_events(self, controller, cylinder):
        """Hand open around the cylinder (set directly), then real events: G pinches, the
        mouse lifts the hand 50 mm in small steps, until the part is being moved."""
        from PySide2 import QtCore
        box = cylinder.Shape.BoundBox
        controller.hand.centre = tuple(box.Center)
        controller.hand.grip = box.XLength + 10.0
        x, y = 300, 300
        self._move_mouse(x, y)
        self._key(QtCore.Qt.Key_G, True)
        self._wait(1.2)
        steps = 10
        dy = max(1, int(round(50.0 / self._mm_per_px(x, y) / steps)))
        for i in range(steps):
            y -= dy
            self._move_mouse(x, y)
            self._wait(0.06)
        self._wait(0.3)
        self.assertEqual(controller.session.state, "MANIPULATE")
        self.assertIsNotNone(controller.session.active)

    def _assert_back_and_clean(self, doc, cylinder, before, log):
        self.assertIsNone(hgui._HapticGraspController.session)
        self.assertTrue(hs.same_placement(cylinder.Placement, before), cylinder.Placement)
        self.assertEqual(doc.UndoCount, 0)
        self.assertFalse(doc.HasPendingTransaction)
        self.assertEqual(log.errors, [])

    def _interrupt_mid_move(self, doc_name, interrupt):
        """The mouse hand grasps and lifts the cylinder with real events, then
        `interrupt(controller)`: the part must be back, with nothing left open."""
        doc, cylinder = self._cylinder_doc(doc_name)
        before = App.Placement(cylinder.Placement)
        controller = None
        with _ErrorLog() as log:
            try:
                controller = self._start_mouse_hand()
                self._grasp_and_lift_with_events(controller, cylinder)
                self.assertGreater((cylinder.Placement.Base - before.Base).Length, 5.0)
                interrupt(controller)
                self._wait(0.3)
            finally:
                if controller is not None:
                    controller.stop()
                    if controller.panel is not None:
                        controller.panel.reject()
                    controller.device = "demo"
                self._wait(0.1)
        self._assert_back_and_clean(doc, cylinder, before, log)
        App.closeDocument(doc.Name)

    def test_esc_mid_move_puts_the_part_back_with_no_transaction_left(self):
        from PySide2 import QtCore

        def escape(_controller):
            self._key(QtCore.Qt.Key_Escape, True)
            self._key(QtCore.Qt.Key_Escape, False)

        self._interrupt_mid_move("HapticGraspEsc", escape)

    def test_closing_the_panel_mid_move_puts_the_part_back_with_no_transaction_left(self):
        from PySide2 import QtWidgets

        def close_panel(controller):
            self.assertIsNotNone(controller.panel)
            click_task_close(self)   # the task dialog's own Close button, as the user clicks it
            self._wait(0.3)
            self.assertIsNone(controller.panel)
            self.assertFalse(Gui.Control.activeDialog())

        self._interrupt_mid_move("HapticGraspClose", close_panel)

    # --- HID devices in the picker (the module's fake transport, test only) --------------
    def test_the_picker_lists_an_attached_spacemouse_and_says_when_none_is(self):
        from PySide2 import QtCore, QtWidgets
        from freecad.hapticgrasp import _hapticgrasp as core
        from freecad.hapticgrasp import panel as hpanel
        Gui.activateWorkbench("HapticGraspWorkbench")
        controller = hgui._HapticGraspController
        feed = core._use_fake_hid()
        try:
            panel = controller.show_panel()   # nothing attached
            combo = panel.form.findChild(QtWidgets.QComboBox, "HapticGrasp_DeviceCombo")
            none = combo.findText(hpanel.NO_HID)
            self.assertGreaterEqual(none, 0)
            self.assertFalse(combo.model().item(none).isEnabled())
            self.assertIn("No SpaceMouse or HID device attached", panel.message.text())
            panel.reject()
            QtWidgets.QApplication.processEvents()
            feed.add_device("/dev/hidraw-test0", 0x046D, 0xC626, "SpaceNavigator")
            panel = controller.show_panel()
            combo = panel.form.findChild(QtWidgets.QComboBox, "HapticGrasp_DeviceCombo")
            item = combo.findData("spacemouse:/dev/hidraw-test0")
            self.assertGreaterEqual(item, 0)
            self.assertTrue(combo.model().item(item).isEnabled())
            self.assertEqual(combo.itemText(item), "SpaceNavigator (hidraw-test0)")
            self.assertEqual(combo.itemData(item, QtCore.Qt.ToolTipRole), "SpaceMouse, /dev/hidraw-test0")
            combo.setCurrentIndex(item)
            self.assertEqual(controller.device, "spacemouse:/dev/hidraw-test0")
            panel.reject()
            QtWidgets.QApplication.processEvents()
        finally:
            controller.device = "demo"
            if controller.panel is not None:
                controller.panel.reject()
            core._use_real_hid()

    def test_a_spacemouse_in_the_gui_moves_the_part_and_an_unplugged_one_is_reported(self):
        import struct
        from PySide2 import QtWidgets
        from freecad.hapticgrasp import _hapticgrasp as core
        doc, cylinder = self._cylinder_doc("HapticGraspSpaceMouse")
        before = App.Placement(cylinder.Placement)
        controller = hgui._HapticGraspController
        path = "/dev/hidraw-test0"
        feed = core._use_fake_hid()
        errors = []
        try:
            Gui.activateWorkbench("HapticGraspWorkbench")
            controller.device = "spacemouse:" + path   # attached later: Start says why not
            with _ErrorLog() as log:
                self._start_and_build()
                errors = list(log.errors)
            self.assertIsNone(controller.session)
            self.assertEqual(len(errors), 1, errors)
            self.assertIn(path, errors[0])
            self.assertIn(path, controller.panel.message.text())
            self.assertTrue(hs.same_placement(cylinder.Placement, before))
            feed.add_device(path, 0x046D, 0xC626, "SpaceNavigator")
            with _ErrorLog() as log:
                self._start_and_build()
                self.assertIsNotNone(controller.session)
                self.assertIn("SpaceNavigator", controller.session.core.device_name)
                self._wait(1.5)   # at rest (silent) longer than its 1 s timeout: no fault
                self.assertEqual(controller.session.fault, "none")
                # Straight down onto the cylinder (hand above it), pinch, lift.
                box = cylinder.Shape.BoundBox
                start_z = controller.session.hand_at(0)[2].z
                drop = start_z - box.Center.z        # the grip centre from above to the centre

                def hold(report, seconds):
                    end = time.monotonic() + seconds
                    while time.monotonic() < end and controller.session is not None:
                        feed.queue_report(path, report)
                        self._wait(0.05)

                # full deflection down: 150 mm/s; stop a little early, then let go
                hold(struct.pack("<Bhhh", 1, 0, 0, 350), max(0.0, drop / 150.0 - 0.02))
                hold(struct.pack("<Bhhh", 1, 0, 0, 0), 0.2)
                hold(bytes([3, 1]), 1.2)                               # button 1: pinch
                hold(struct.pack("<Bhhh", 1, 0, 0, -175), 0.6)         # up
                hold(struct.pack("<Bhhh", 1, 0, 0, 0), 0.3)
                states = controller.session.state if controller.session else None
                index_force = controller.panel.fields["index"].text()
                moved_while_held = (cylinder.Placement.Base - before.Base).z
                feed.remove_device(path)                               # unplugged mid-move
                self._wait(2.5)
                errors = list(log.errors)
            print("spacemouse in the GUI: state %s, part lifted %.1f mm before the unplug" % (states, moved_while_held))
            self.assertEqual(states, "MANIPULATE")
            self.assertIn("not displayed: input-only device", index_force)
            self.assertGreater(moved_while_held, 10.0)
            self.assertIsNone(controller.session)        # the fault stopped it
            self.assertTrue(any("device fault (silent)" in e for e in errors), errors)
            self.assertTrue(hs.same_placement(cylinder.Placement, before), cylinder.Placement)
            self.assertEqual(doc.UndoCount, 0)
            self.assertFalse(doc.HasPendingTransaction)
        finally:
            controller.stop()
            controller.device = "demo"
            if controller.panel is not None:
                controller.panel.reject()
            core._use_real_hid()
            self._wait(0.1)
        App.closeDocument(doc.Name)

    def test_the_overlay_shows_every_fingertip_a_device_has(self):
        # A three-fingertip device: the third sphere and its force arrow appear, the
        # fourth and fifth stay hidden; two fingertips again hide the third.
        from pivy import coin
        from freecad.hapticgrasp import overlay as hoverlay
        doc = App.newDocument("HapticGraspOverlay3")
        overlay = hoverlay.HapticOverlay(Gui.ActiveDocument.ActiveView)
        try:
            V = App.Vector
            hand = (V(10, 0, 0), V(-10, 0, 0), V(0, 0, 50))
            overlay.update("GRASP", hand, (V(-1, 0, 0), V(1, 0, 0)), None, False,
                           more=[(V(0, 10, 0), V(0, -2, 0))])
            (third, move), (fourth, _) = overlay.extra[0], overlay.extra[1]
            self.assertEqual(third.whichChild.getValue(), coin.SO_SWITCH_ALL)
            self.assertEqual(fourth.whichChild.getValue(), coin.SO_SWITCH_NONE)
            self.assertEqual(tuple(move.translation.getValue()), (0.0, 10.0, 0.0))
            self.assertEqual(overlay.extra_arrows[0][0].whichChild.getValue(), coin.SO_SWITCH_ALL)
            tip = overlay.extra_arrows[0][1].point[1].getValue()
            self.assertAlmostEqual(tip[1], 10.0 - 2 * hoverlay.ARROW_MM_PER_N, places=4)
            overlay.update("GRASP", hand, (V(-1, 0, 0), V(1, 0, 0)), None, False)
            self.assertEqual(third.whichChild.getValue(), coin.SO_SWITCH_NONE)
            self.assertEqual(overlay.extra_arrows[0][0].whichChild.getValue(), coin.SO_SWITCH_NONE)
        finally:
            overlay.remove()
            App.closeDocument(doc.Name)

    @staticmethod
    def _overlay_nodes():
        from pivy import coin
        search = coin.SoSearchAction()
        search.setName(coin.SbName("HapticGraspOverlay"))
        search.setInterest(coin.SoSearchAction.ALL)
        search.apply(Gui.ActiveDocument.ActiveView.getSceneGraph())
        return search.getPaths().getLength()


COMMANDS = ("HapticGrasp_Start", "HapticGrasp_Stop", "HapticGrasp_MarkGraspable", "HapticGrasp_SplitSolids",
            "HapticGrasp_Review")


def svg_view_box(path):
    """The viewBox of an SVG file, as four floats (the SVG is parsed: it must be well formed)."""
    import xml.etree.ElementTree as ElementTree
    root = ElementTree.parse(path).getroot()
    return tuple(float(v) for v in root.get("viewBox", "").split())


def draw_svg(path, size):
    """The SVG drawn into a transparent size x size QImage, as FreeCAD draws icons."""
    from PySide import QtCore, QtGui, QtSvg
    image = QtGui.QImage(size, size, QtGui.QImage.Format_ARGB32_Premultiplied)
    image.fill(QtCore.Qt.transparent)
    painter = QtGui.QPainter(image)
    QtSvg.QSvgRenderer(path).render(painter)
    painter.end()
    return image


def likeness(image, other, tolerance=8):
    """The share of pixels two QImages of one size have alike (RGBA within tolerance)."""
    if image.size() != other.size():
        return 0.0
    alike = 0
    for y in range(image.height()):
        for x in range(image.width()):
            a, b = image.pixelColor(x, y), other.pixelColor(x, y)
            alike += max(abs(a.red() - b.red()), abs(a.green() - b.green()), abs(a.blue() - b.blue()),
                         abs(a.alpha() - b.alpha())) <= tolerance
    return alike / float(image.width() * image.height())


class WorkbenchConventions(unittest.TestCase):
    """Icons and shortcuts as FreeCAD's own workbenches have them: the workbench, each
    command and the preferences group show an SVG icon from the package, and each command
    has a two-key shortcut no command of the loaded workbenches has."""

    def setUp(self):
        Gui.activateWorkbench("HapticGraspWorkbench")

    def assert_svg_icon(self, path):
        from PySide import QtSvg
        self.assertTrue(os.path.isfile(path), path)
        self.assertTrue(os.path.realpath(path).startswith(os.path.realpath(hgui.icon(""))), path)
        self.assertEqual(svg_view_box(path), (0.0, 0.0, 64.0, 64.0), path)
        self.assertTrue(QtSvg.QSvgRenderer(path).isValid(), path)

    def test_the_workbench_and_every_command_show_an_svg_icon_of_the_package(self):
        self.assertIn("freecad.hapticgrasp.init_gui", sys.modules)   # FreeCAD imported it at start-up
        self.assert_svg_icon(Gui.getWorkbench("HapticGraspWorkbench").Icon)
        for name in COMMANDS:
            command = Gui.Command.get(name)
            self.assert_svg_icon(command.getInfo()["pixmap"])
            actions = command.getAction()
            self.assertTrue(actions, name)
            self.assertFalse(actions[0].icon().isNull(), name)

    def test_every_command_has_its_own_two_key_shortcut(self):
        # Draft has "H, A" and "H, S", the Sketcher single letters: load them and compare.
        for workbench in ("PartWorkbench", "PartDesignWorkbench", "SketcherWorkbench", "DraftWorkbench"):
            Gui.activateWorkbench(workbench)
        Gui.activateWorkbench("HapticGraspWorkbench")
        taken = {}
        for name in Gui.Command.listAll():
            shortcut = Gui.Command.get(name).getShortcut()
            if shortcut:
                taken.setdefault(shortcut, []).append(name)
        self.assertIn("Draft_SubelementHighlight", taken.get("H, S", []))   # Draft's were loaded
        for name in COMMANDS:
            shortcut = Gui.Command.get(name).getShortcut()
            self.assertEqual(shortcut, hgui.ACCELS[name])
            self.assertRegex(shortcut, r"^H, [A-Z]$")
            self.assertEqual(taken[shortcut], [name])

    def test_the_preferences_group_has_its_icon(self):
        # FreeCAD shows a "missing icon" picture for a group without one, never a null
        # icon: compare what the dialog shows with the package's SVG drawn at that size.
        from PySide import QtCore, QtGui
        seen = {}

        def inspect():   # runs inside the modal dialog's event loop
            dialog = QtGui.QApplication.activeModalWidget()
            try:
                for listing in dialog.findChildren(QtGui.QListWidget):
                    for row in range(listing.count()):
                        item = listing.item(row)
                        seen[item.text()] = item.icon().pixmap(48, 48).toImage()
            finally:
                dialog.reject()

        QtCore.QTimer.singleShot(300, inspect)
        Gui.runCommand("Std_DlgPreferences")
        self.assertIn("Haptic Grasp", seen)
        drawn = draw_svg(hgui.icon("preferences-haptic_grasp.svg"), 48)
        print("preferences icons like the package's: %s" % {k: round(likeness(v, drawn), 3) for k, v in seen.items()})
        self.assertLess(likeness(seen["General"], drawn), 0.9)   # FreeCAD's own group
        self.assertGreater(likeness(seen["Haptic Grasp"], drawn), 0.98)


def task_scroll_area(form):
    """The task view's QScrollArea that holds a task panel's form."""
    from PySide import QtGui
    parent = form.parentWidget()
    while parent is not None and not isinstance(parent, QtGui.QScrollArea):
        parent = parent.parentWidget()
    return parent


def _label_text_width(label, width):
    """How wide a QLabel's text is laid out in `width` px (its widest line: a word wider
    than `width` makes it wider), measured as QLabel draws: rich text as a QTextDocument,
    plain text with the font's metrics."""
    from PySide import QtCore, QtGui
    text = label.text()
    if label.textFormat() == QtCore.Qt.RichText or (label.textFormat() == QtCore.Qt.AutoText
                                                    and QtGui.Qt.mightBeRichText(text)):
        document = QtGui.QTextDocument()
        document.setDefaultFont(label.font())
        document.setDocumentMargin(0)
        document.setHtml(text)
        document.setTextWidth(width if label.wordWrap() else -1)
        return document.idealWidth()
    metrics = label.fontMetrics()
    if label.wordWrap():
        return metrics.boundingRect(QtCore.QRect(0, 0, width, 1 << 20), int(QtCore.Qt.TextWordWrap), text).width()
    return max(metrics.horizontalAdvance(line) for line in text.split("\n"))


def _combo_item_widths(combo):
    """[(text, px)]: how wide a QComboBox must be to show each of its items whole, computed
    as QComboBox computes its size hint (the style's size around the text and the icon)."""
    from PySide import QtCore, QtGui
    option = QtGui.QStyleOptionComboBox()
    option.initFrom(combo)
    option.editable = combo.isEditable()
    metrics = combo.fontMetrics()
    widths = []
    for row in range(combo.count()):
        icon = 0 if combo.itemIcon(row).isNull() else combo.iconSize().width() + 4
        content = QtCore.QSize(metrics.horizontalAdvance(combo.itemText(row)) + icon, metrics.height())
        size = combo.style().sizeFromContents(QtGui.QStyle.CT_ComboBox, option, content, combo)
        widths.append((combo.itemText(row), size.width()))
    return widths


def clipped(form):
    """What of a task panel does not fit the task view at its width, one line each: the
    panel scrolling sideways; a label, button, combo box or check box reaching outside the
    view, narrower than its size hint (buttons, check boxes: their text is cut), a combo box
    too narrow for any of its items, or a label whose text is wider than it (a line that does
    not wrap, a word too long to wrap) or taller."""
    from PySide import QtCore, QtGui
    area = task_scroll_area(form)
    viewport = area.viewport()
    problems = []
    if area.horizontalScrollBar().maximum() > 0:
        problems.append("the panel scrolls sideways by %d px" % area.horizontalScrollBar().maximum())
    for widget in form.findChildren(QtGui.QWidget):
        if not isinstance(widget, (QtGui.QLabel, QtGui.QPushButton, QtGui.QComboBox, QtGui.QCheckBox)):
            continue
        if not widget.isVisibleTo(form):
            continue
        text = widget.currentText() if isinstance(widget, QtGui.QComboBox) else widget.text()
        name = "%s %s %r" % (type(widget).__name__, widget.objectName(), text[:40])
        left = widget.mapTo(viewport, QtCore.QPoint(0, 0)).x()
        if left < 0 or left + widget.width() > viewport.width():
            problems.append("%s: x %d..%d in a view %d px wide" % (name, left, left + widget.width(),
                                                                  viewport.width()))
        if isinstance(widget, QtGui.QLabel):
            room = widget.contentsRect().width()
            need = _label_text_width(widget, room)
            if need > room:
                problems.append("%s: text %d px wide in %d px" % (name, need, room))
            if widget.wordWrap() and widget.height() < widget.heightForWidth(widget.width()):
                problems.append("%s: %d px high, its text %d px" % (name, widget.height(),
                                                                     widget.heightForWidth(widget.width())))
        elif isinstance(widget, QtGui.QComboBox):
            for item, need in _combo_item_widths(widget):
                if need > widget.width():
                    problems.append("%s: %d px wide, item %r needs %d" % (name, widget.width(), item, need))
        elif widget.width() < widget.sizeHint().width():
            problems.append("%s: %d px wide, needs %d" % (name, widget.width(), widget.sizeHint().width()))
    return problems


def settle(seconds=0.3):
    """Lets Qt lay the panels out (and the timers tick) for a while."""
    from PySide import QtGui
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        QtGui.QApplication.processEvents()
        time.sleep(0.01)


class LivePanelWidth(unittest.TestCase):
    """The live session's task panel fits the combo view at its default width (a fresh
    profile's: 264 px here) idle, while the models are built and while a session runs with
    every read-out filled: nothing is cut and nothing scrolls sideways. A screenshot of the
    running panel: build/freecad/screenshots/TestHapticGraspGui_live_panel.png."""

    maxDiff = None   # every clipped widget in the failure message

    def test_the_live_panel_fits_the_combo_view(self):
        from PySide import QtGui
        Gui.activateWorkbench("HapticGraspWorkbench")
        controller = hgui._HapticGraspController
        doc, cylinder = cylinder_doc("HapticGraspWidth")
        controller.device = "demo"
        try:
            panel = controller.show_panel()
            self.assertIsNotNone(panel)
            settle()
            area = task_scroll_area(panel.form)
            print("combo view %d px wide, the task view's viewport %d px"
                  % (Gui.getMainWindow().findChild(QtGui.QDockWidget, "Combo View").width(),
                     area.viewport().width()))
            self.assertEqual(clipped(panel.form), [], "idle")
            panel.set_building(True)
            panel.show_build(3, 12, "Cylinder001")
            settle()
            self.assertEqual(clipped(panel.form), [], "building")
            panel.set_building(False)
            Gui.Selection.addSelection(cylinder)
            Gui.runCommand("HapticGrasp_Start")
            deadline = time.monotonic() + 15
            while time.monotonic() < deadline and controller.session is not None and not (
                    controller.session.state == "MANIPULATE" and "Hz" in panel.fields["rate"].text()):
                settle(0.02)
            self.assertEqual(controller.session.state, "MANIPULATE")
            self.assertNotIn("-", [label.text() for label in panel.fields.values()])
            problems = clipped(panel.form)
            os.makedirs(SCREENSHOT_DIR, exist_ok=True)
            panel.form.grab().save(os.path.join(SCREENSHOT_DIR, "TestHapticGraspGui_live_panel.png"))
            self.assertEqual(problems, [], "running")
        finally:
            controller.stop()
            if controller.panel is not None:
                controller.panel.reject()
            settle(0.1)
            App.closeDocument(doc.Name)


class ReviewPanelGui(unittest.TestCase):
    """The Review panel in the real GUI: a session recorded on a saved document is played
    back by moving the part's view provider only (its root SoTransform shows the recorded
    pose; the document's Placement, undo stack and modified flag stay as they are), the hand
    is drawn by the overlay, playback advances the cursor, an event in the list jumps to its
    time, Apply is one undo step and the task dialog's Close button puts the view back where
    the document has the part and removes the overlay."""

    def setUp(self):
        import tempfile
        self.dir = tempfile.mkdtemp()

    def tearDown(self):
        import shutil
        shutil.rmtree(self.dir, ignore_errors=True)

    def _record(self):
        """A saved document holding a cylinder that the demo hand lifts, carries and puts
        down in a recorded session; the live move undone. Returns (doc, cylinder, path)."""
        from PySide2 import QtWidgets
        doc, cylinder = cylinder_doc("HapticGraspReview", self.dir)
        s = hs.HapticSession(doc, scene=True)
        try:
            keys, frame = hs.demo_script(s.parts[0])
            s.use_hand_script(keys, frame)
            s.start(record=True)
            deadline = time.monotonic() + 10.0
            while s.running and time.monotonic() < deadline and s.tick()["time_s"] < 2.6:
                time.sleep(0.01)
        finally:
            s.stop()
        self.assertEqual(s.moves, 1, s.messages)
        doc.undo()   # the reviewer sees the document as it was
        doc.recompute()
        Gui.runCommand("Std_Save")   # as the user saves: App's save() leaves the GUI's Modified set
        QtWidgets.QApplication.processEvents()
        self.assertFalse(Gui.getDocument(doc.Name).Modified)
        return doc, cylinder, s.recording

    @staticmethod
    def _shown_translation(obj):
        """Where the 3D view shows obj: its view provider's root SoTransform (mm)."""
        transform = obj.ViewObject.RootNode.getChild(0)
        return App.Vector(*transform.translation.getValue().getValue())

    def test_the_review_panel_fits_the_combo_view(self):
        # At the combo view's default width, mid-carry (the longest state text) and with the
        # longest event in the list: nothing cut, nothing scrolling sideways.
        from freecad.hapticgrasp import review_panel
        self.maxDiff = None   # every clipped widget in the failure message
        Gui.activateWorkbench("HapticGraspWorkbench")
        doc, cylinder, path = self._record()
        panel = review_panel.open_review(path, doc)
        try:
            panel.seek(1.2)
            settle()
            self.assertEqual(panel.state_label.text().split()[0], "MANIPULATE")
            problems = clipped(panel.form)
            os.makedirs(SCREENSHOT_DIR, exist_ok=True)
            panel.form.grab().save(os.path.join(SCREENSHOT_DIR, "TestHapticGraspGui_review_panel_width.png"))
            self.assertEqual(problems, [])
        finally:
            panel.reject()
            settle(0.1)
            App.closeDocument(doc.Name)

    def test_playback_moves_the_view_only_and_apply_is_one_undo_step(self):
        from PySide2 import QtCore, QtWidgets
        from freecad.hapticgrasp import review_panel
        Gui.activateWorkbench("HapticGraspWorkbench")
        self.assertIsNotNone(Gui.Command.get("HapticGrasp_Review"))
        doc, cylinder, path = self._record()
        before = App.Placement(cylinder.Placement)
        with _ErrorLog() as log:
            panel = review_panel.open_review(path, doc)
            self.assertIs(review_panel.current(), panel)
            self.assertTrue(Gui.Control.activeDialog())
            review = panel.review
            self.assertEqual(review.warnings, [])
            self.assertEqual(review.moved, [0])
            # Mid-carry: the view shows the recorded pose, the document is untouched.
            panel.seek(1.2)
            QtWidgets.QApplication.processEvents()
            recorded = review.placements_at(1.2)[0]
            self.assertGreater((recorded.Base - before.Base).Length, 20.0)
            self.assertLess((self._shown_translation(cylinder) - recorded.Base).Length, 1e-3)
            self.assertTrue(hs.same_placement(cylinder.Placement, before, 1e-12))
            self.assertEqual((doc.UndoCount, Gui.getDocument(doc.Name).Modified), (0, False))
            self.assertEqual(panel.state_label.text().split()[0], "MANIPULATE")
            self.assertGreater(HapticGraspGui._overlay_nodes(), 0)
            os.makedirs(os.path.dirname(SCREENSHOT), exist_ok=True)
            Gui.ActiveDocument.ActiveView.viewFront()
            Gui.SendMsgToActiveView("ViewFit")
            Gui.ActiveDocument.ActiveView.saveImage(SCREENSHOT.replace(".png", "_review.png"), 640, 480)
            panel.form.grab().save(SCREENSHOT.replace(".png", "_review_panel.png"))
            # Playing at 4x from 0 advances the cursor by the wall time.
            panel.seek(0.0)
            panel.speed_combo.setCurrentIndex(review_panel.SPEEDS.index(4.0))
            panel.play_button.click()
            self.assertTrue(panel.playing)
            start = time.monotonic()
            while time.monotonic() - start < 0.5:
                QtWidgets.QApplication.processEvents()
                time.sleep(0.005)
            panel.play_button.click()
            self.assertFalse(panel.playing)
            self.assertGreater(panel.t, 0.5)   # 4 x 0.5 s of wall time, less the GUI's delays
            # An event in the list: clicking it puts the cursor at its time.
            self.assertGreater(panel.events_list.count(), 0)
            item = panel.events_list.item(panel.events_list.count() - 1)
            panel._jump(item)
            self.assertAlmostEqual(panel.t, item.data(QtCore.Qt.UserRole), places=9)
            # Apply at the end: the document's part where the session put it, one undo step.
            panel.seek(review.duration_s)
            panel.apply_button.click()
            end = review.placements_at(review.duration_s)[0]
            self.assertTrue(hs.same_placement(cylinder.Placement, end, 1e-6))
            self.assertEqual(doc.UndoNames, ["Apply review pose"])
            # Back to the start, then Close: the view shows the document's placement again.
            panel.seek(0.0)
            self.assertGreater((self._shown_translation(cylinder) - cylinder.Placement.Base).Length, 20.0)
            click_task_close(self)
            QtWidgets.QApplication.processEvents()
            self.assertFalse(Gui.Control.activeDialog())
            self.assertIsNone(review_panel.current())
            self.assertLess((self._shown_translation(cylinder) - cylinder.Placement.Base).Length, 1e-3)   # Coin keeps floats
            self.assertEqual(HapticGraspGui._overlay_nodes(), 0)
        self.assertEqual(log.errors, [])
        App.closeDocument(doc.Name)


    def test_the_review_command_opens_the_chosen_file_and_says_why_it_cannot(self):
        """The command as the user runs it, the file dialog and the message box answered by
        the test: a recording opens the panel; a file that is not one is named in an error
        box and opens nothing."""
        from PySide import QtGui   # the shim review_panel uses
        from freecad.hapticgrasp import review_panel
        doc, _cylinder, path = self._record()
        bad = os.path.join(self.dir, "not-a-recording.mcap")
        with open(bad, "w") as f:
            f.write("hello\n")
        errors = []
        dialog, critical = QtGui.QFileDialog.getOpenFileName, QtGui.QMessageBox.critical
        try:
            QtGui.QMessageBox.critical = staticmethod(lambda _parent, _title, text: errors.append(text))
            QtGui.QFileDialog.getOpenFileName = staticmethod(lambda *args: (bad, ""))
            Gui.runCommand("HapticGrasp_Review")
            self.assertFalse(Gui.Control.activeDialog())
            self.assertEqual(len(errors), 1)
            self.assertIn("not-a-recording.mcap cannot be reviewed: ", errors[0])
            QtGui.QFileDialog.getOpenFileName = staticmethod(lambda *args: (path, ""))
            Gui.runCommand("HapticGrasp_Review")
            panel = review_panel.current()
            self.assertIsNotNone(panel)
            self.assertEqual(panel.review.path, path)
            self.assertIs(panel.review.doc, doc)
            self.assertIsNone(QtGui.QApplication.overrideCursor())   # the wait cursor is gone
            panel.reject()
        finally:
            QtGui.QFileDialog.getOpenFileName, QtGui.QMessageBox.critical = dialog, critical
        self.assertFalse(Gui.Control.activeDialog())
        App.closeDocument(doc.Name)


AS1 = os.path.join(os.environ.get("HG_TEST_DATA_DIR", ""), "as1-oc-214.stp")
IMPORT_PREFERENCES = "User parameter:BaseApp/Preferences/Mod/Import"


def _exact_box(shape):
    """The shape's bounding box from its geometry: on a copy without the display's
    triangulation (in FreeCAD 0.20.2 optimalBoundingBox(False) still used it: boxes of AS1's
    shown solids came out up to 0.04 mm larger)."""
    b = shape.copy().optimalBoundingBox()
    return (b.XMin, b.YMin, b.ZMin, b.XMax, b.YMax, b.ZMax)


class StepAssemblies(unittest.TestCase):
    """The public AS1 assembly (18 solids, 5 distinct shapes) through FreeCAD's own STEP
    importer (ImportGui.insert), in the structures its preferences give (measured on
    FreeCAD 0.20.2; keys in User parameter:BaseApp/Preferences/Mod/Import):
    - defaults (hSTEP/ReadShapeCompoundMode true, UseLinkGroup true): the whole file merged
      into ONE Part::Feature, a compound of the 18 solids: one part of 18 solids;
    - ReadShapeCompoundMode false, UseLinkGroup true: App::LinkGroups and App::Links, with
      link arrays (the rod's 2 nuts; the 2 l-bracket assemblies, each a hidden LinkGroup
      holding the bracket and a 3-element array of the hidden nut-bolt LinkGroup): 18 parts;
    - ReadShapeCompoundMode false, UseLinkGroup false: an App::Part tree of 18 Part::Features.
    Every solid must be collected once and touchable where the view shows it: the parts'
    global solids' boxes equal, as a multiset, those of the file read by Part.Shape.read."""

    def setUp(self):
        self.assertTrue(os.path.isfile(AS1), AS1)
        shape = Part.Shape()
        shape.read(AS1)
        self.assertEqual(len(shape.Solids), 18)
        self.expected = [_exact_box(s) for s in shape.Solids]
        self.docs = []

    def tearDown(self):
        for key in ("ReadShapeCompoundMode", "UseLinkGroup"):   # back to the defaults
            App.ParamGet(IMPORT_PREFERENCES + "/hSTEP").RemBool(key)
            App.ParamGet(IMPORT_PREFERENCES).RemBool(key)
        for doc in self.docs:
            App.closeDocument(doc.Name)

    def import_as1(self, name, merge=None, link_group=None):
        """AS1 inserted by the GUI's STEP importer into a new document; None leaves a
        preference at its default."""
        import ImportGui
        for group, key, value in ((IMPORT_PREFERENCES + "/hSTEP", "ReadShapeCompoundMode", merge),
                                  (IMPORT_PREFERENCES, "UseLinkGroup", link_group)):
            if value is None:
                App.ParamGet(group).RemBool(key)
            else:
                App.ParamGet(group).SetBool(key, value)
        doc = App.newDocument(name)
        self.docs.append(doc)
        ImportGui.insert(AS1, doc.Name)
        doc.recompute()
        doc.clearUndos()
        return doc

    def assertSameBoxes(self, got, tol=1e-3):
        """got and the file's solids' boxes are the same multiset within tol (mm)."""
        self.assertEqual(len(got), len(self.expected))
        left = list(got)
        for box in self.expected:
            match = [b for b in left if all(abs(x - y) <= tol for x, y in zip(b, box))]
            self.assertTrue(match, "no part at %s" % (box,))
            left.remove(match[0])

    def test_default_import_is_one_part_of_18_solids_and_the_split_command_makes_18(self):
        doc = self.import_as1("AS1Default")
        self.assertEqual([o.TypeId for o in doc.Objects], ["Part::Feature"])   # measured: merged
        messages = []
        parts = hs.collect_solids(doc, messages)
        self.assertEqual(len(parts), 1)
        compound = parts[0]
        self.assertEqual(len(compound.global_shape().Solids), 18)
        self.assertSameBoxes([_exact_box(s) for s in compound.global_shape().Solids])
        self.assertEqual(messages, ["%s holds 18 solids, carried as one rigid part; HapticGrasp > Split into "
                                    "solids makes each graspable" % compound.label])
        # The command, on the selection: 18 objects in one undo step.
        Gui.activateWorkbench("HapticGraspWorkbench")
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(compound.obj)
        with _ErrorLog() as log:
            self.assertTrue(Gui.Command.get("HapticGrasp_SplitSolids").isActive())
            Gui.runCommand("HapticGrasp_SplitSolids")
        Gui.Selection.clearSelection()
        self.assertEqual(log.errors, [])
        self.assertEqual(doc.UndoNames, ["Split into solids"])
        messages = []
        parts = hs.collect_solids(doc, messages)
        self.assertEqual([p.label for p in parts], ["%s solid %d" % (compound.label, n) for n in range(1, 19)])
        self.assertEqual(messages, [])
        self.assertSameBoxes([_exact_box(p.global_shape()) for p in parts])
        doc.undo()
        self.assertEqual([p.label for p in hs.collect_solids(doc, [])], [compound.label])

    def test_link_group_import_is_18_parts_each_where_the_view_shows_it(self):
        doc = self.import_as1("AS1Links", merge=False, link_group=True)
        types = {o.TypeId for o in doc.Objects}
        self.assertEqual(types, {"App::LinkGroup", "App::Link", "Part::Feature"})
        self.assertTrue(any(getattr(o, "ElementCount", 0) > 1 for o in doc.Objects if o.TypeId == "App::Link"))
        parts = hs.collect_solids(doc, [])
        print("AS1 with links: %s" % ", ".join(p.label for p in parts))
        self.assertEqual(len(parts), 18)
        self.assertTrue(all(len(p.global_shape().Solids) == 1 for p in parts))
        self.assertSameBoxes([_exact_box(p.global_shape()) for p in parts])
        self.assertEqual(len({hs.share_key(p) for p in parts}), 5)   # plate, bracket, rod, bolt, nut
        # Each part's placement is written to an object it owns: a link (array element) or
        # an unshared object; never a hidden link target's object.
        self.assertTrue(all(p.obj.TypeId == "App::Link" or p.obj == p.leaf for p in parts))

    def test_app_part_import_is_18_parts_each_where_the_view_shows_it(self):
        doc = self.import_as1("AS1Parts", merge=False, link_group=False)
        self.assertIn("App::Part", {o.TypeId for o in doc.Objects})
        self.assertNotIn("App::Link", {o.TypeId for o in doc.Objects})
        parts = hs.collect_solids(doc, [])
        self.assertEqual(len(parts), 18)
        self.assertEqual({p.obj.TypeId for p in parts}, {"Part::Feature"})
        self.assertSameBoxes([_exact_box(p.global_shape()) for p in parts])
