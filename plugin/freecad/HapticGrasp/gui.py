"""GUI of the HapticGrasp workbench: the Start/Stop, Mark graspable and Split into solids commands, and the
QTimer that drives HapticSession.tick() on the GUI thread (InitGui.py imports this from Initialize())."""
import FreeCAD as App
import FreeCADGui as Gui
from FreeCAD import Qt

from . import icon
from . import session as hs
from . import sounds as hsounds

QT_TRANSLATE_NOOP = Qt.QT_TRANSLATE_NOOP   # marks command texts for translation (FreeCAD's convention:
translate = Qt.translate                   # context = the command's name), translate() what dialogs show

# Shortcuts: FreeCAD's two-key style ("V, F" fits all, "G, L" a sketch line), H for haptics.
# None is one of FreeCAD 0.20.2's default shortcuts (listed from every workbench but Path,
# OpenSCAD and Web: Draft has "H, A" and "H, S"). The Sketcher's single "H" does not get in
# the way: its action is disabled outside a sketch (measured: real X key presses H, M
# marked the selection with the Sketcher workbench loaded before). TestHapticGraspGui
# checks each against the commands of the workbenches it loads.
ACCELS = {
    "HapticGrasp_Start": "H, G",
    "HapticGrasp_Stop": "H, X",
    "HapticGrasp_MarkGraspable": "H, M",
    "HapticGrasp_SplitSolids": "H, P",
    "HapticGrasp_Review": "H, R",
}


class _HapticGraspController:
    """Owns the running session and the QTimer that calls its tick() (30-60 Hz)."""

    session = None
    timer = None
    panel = None      # the task panel (HapticTaskPanel), open while the dialog is shown
    overlay = None    # the Coin overlay (HapticOverlay), present while running
    sounds = None     # SoundBoard, created once
    last_state = "FREE"
    device = "demo"   # the panel's device choice: "demo" (scripted hand), "mouse", "arm"
    #                   (the simulated arm driven by the mouse hand as its target),
    #                   "spacemouse:<path>" or "hid:<path>" (an attached HID device)
    device_layout = ""  # the layout file of a "hid:" device
    hand = None       # MouseHand while the mouse-and-keyboard device (or the arm's target) runs
    hand_clock = None
    events = None     # MouseEvents (Coin callbacks on the 3D view) while it runs
    selected = []     # the selection at Start (the demo hand's target)

    @classmethod
    def show_panel(cls):
        """Opens the task panel (if no other task dialog is open)."""
        if cls.panel is not None and _alive(cls.panel.form):
            return cls.panel
        cls.panel = None   # its dialog was closed without it (FreeCAD closed it): a new one
        from . import panel as hpanel
        panel = hpanel.HapticTaskPanel(cls)
        try:
            if Gui.Control.activeDialog():
                App.Console.PrintWarning("HapticGrasp: another task dialog is open, no haptics panel\n")
                return None
            Gui.Control.showDialog(panel)
        except Exception as e:
            App.Console.PrintWarning("HapticGrasp: cannot show the task panel: %s\n" % e)
            return None
        cls.panel = panel
        return panel

    @classmethod
    def start(cls):
        """Start: the servo loop runs at once on every part's bounding box; the part models
        are built in the background, nearest the hand first, each distinct shape once, and
        each part is felt through its own model as soon as it is in (the panel counts them)."""
        from PySide import QtCore   # FreeCAD's shim
        doc = App.ActiveDocument
        if doc is None:
            App.Console.PrintError("HapticGrasp: no active document\n")
            return
        cls.stop()
        cls._stop_at_quit()
        cls.selected = list(Gui.Selection.getSelection())   # the demo hand's target, if a part
        session = hs.HapticSession(doc, wait=False, scene=True)
        cls.session = session
        cls.show_panel()
        cls.timer = QtCore.QTimer()
        cls.timer.setInterval(20)  # 50 Hz: the session's tick (it hands the build its shapes)
        cls.timer.timeout.connect(cls.tick)
        cls.timer.start()
        App.Console.PrintMessage("HapticGrasp: %d part(s), their models built in the background\n" % len(session.parts))
        cls._launch()

    quit_hooked = False

    @classmethod
    def _stop_at_quit(cls):
        """FreeCAD quitting while haptics run: stop them first, so that the servo thread is
        joined and the recording gets its last chunk and summary (without this the file was
        cut short at exit)."""
        from PySide import QtGui   # FreeCAD's shim: its QtGui holds QApplication
        if not cls.quit_hooked:
            QtGui.QApplication.instance().aboutToQuit.connect(cls.stop)
            cls.quit_hooked = True

    @classmethod
    def cancel_build(cls):
        """The panel's Cancel while building: nothing is kept, haptics do not start."""
        if cls.session is not None and not cls.session.ready:
            cls.session.cancel_build()
        cls.stop()

    @classmethod
    def _launch(cls):
        """The build has finished: choose the device and start the servo loop."""
        session = cls.session
        if cls.panel is not None:
            cls.panel.set_building(False)
        if not session.parts:
            App.Console.PrintError("HapticGrasp: no visible solid to grasp\n")
            cls.stop()
            return
        chosen = getattr(cls, "selected", [])
        selected = [r for r in session.parts if r.obj in chosen or r.leaf in chosen]
        target = selected[0] if selected else session.parts[0]
        view = getattr(Gui.ActiveDocument, "ActiveView", None) if Gui.ActiveDocument else None
        if cls.device in ("mouse", "arm") and view is not None and hasattr(view, "addEventCallbackPivy"):
            # A hand fed from Python: the mouse and keyboard move a MouseHand, the timer
            # feeds session.set_hand() with its tick; silent 0.5 s -> watchdog fault. With
            # the simulated arm that hand is the target its operator pulls the arm to.
            import time
            if cls.device == "arm":
                rest = session.use_simulated_arm(target, hold_s=0.5)
                cls.hand = _arm_hand_for(view, target, rest)
            else:
                session.use_hand_input(hold_s=0.5)
                cls.hand = _mouse_hand_for(view, target)
            cls.hand_clock = time.monotonic()
            cls.events = MouseEvents(view, cls)
        elif cls.device.startswith(("spacemouse:", "hid:")):
            if not cls._use_hid_device(session, target):
                cls.stop()   # nothing started, the document untouched; the panel says why
                return
        else:
            # The scripted demo hand grasping the selected part (or the first solid),
            # lifting it, carrying it 100 mm along y, putting it down.
            keys, frame = hs.demo_script(target)
            session.use_hand_script(keys, frame)
        try:
            session.start()   # with the force parameters of the preferences
        except ValueError as e:
            App.Console.PrintError("HapticGrasp: bad force parameter (Preferences > Haptic Grasp): %s\n" % e)
            cls.stop()   # the mouse callbacks, if any
            return
        if cls.hand is not None:   # the hand input device exists once started
            session.set_hand(*cls.hand.tick(0.0))
        cls.last_state = "FREE"
        if cls.sounds is None:
            cls.sounds = hsounds.SoundBoard()
        cls.show_panel()
        if cls.panel is not None:
            cls.panel.set_running(True)
            cls.panel.show_message("")   # an earlier "cannot use ..." no longer applies
        if view is not None and hasattr(view, "getSceneGraph"):
            try:
                from . import overlay as hoverlay
                cls.overlay = hoverlay.HapticOverlay(view)
            except Exception as e:  # no pivy: run without the overlay
                App.Console.PrintWarning("HapticGrasp: no 3D overlay: %s\n" % e)
                cls.overlay = None
        App.Console.PrintMessage("HapticGrasp: started with %d part(s)\n" % len(session.parts))

    @classmethod
    def _use_hid_device(cls, session, target):
        """Opens the picked SpaceMouse / HID device for `session`, its hand starting above
        `target` (a PartRef; a SpaceMouse: grip centre half the part's size + 20 mm above its centre,
        open wider than the part; a layout: the device frame's origin at the part's centre).
        False, with the reason in the report view and the panel, when it cannot be opened."""
        kind, path = cls.device.split(":", 1)
        box = hs.global_bound_box(target)
        size = box.DiagonalLength
        try:
            if kind == "spacemouse":
                session.use_spacemouse(path, start=box.Center + App.Vector(0, 0, 0.5 * size + 20.0),
                                       open_mm=size + 40.0, closed_mm=0.0)
            else:
                session.use_hid(cls.device_layout, path, origin=box.Center)
        except (RuntimeError, ValueError) as e:   # core.DeviceError / core.LayoutError
            text = translate("HapticGrasp", "Cannot use %s: %s") % (path, e)
            App.Console.PrintError("HapticGrasp: %s\n" % text)
            cls.show_panel()
            if cls.panel is not None:
                cls.panel.show_message(text)
            return False
        return True

    @classmethod
    def tick(cls):
        if cls.session is None:
            return
        if not cls.session.ready:   # still building the models
            try:
                finished = cls.session.poll_build()
                if cls.panel is not None:
                    cls.panel.show_build(*cls.session.build_progress())
                if finished:
                    cls._launch()
            except Exception as e:  # never let the timer die silently
                App.Console.PrintError("HapticGrasp: %s\n" % e)
                cls.stop()
            return
        try:
            if cls.hand is not None:
                import time
                now = time.monotonic()
                dt, cls.hand_clock = now - cls.hand_clock, now
                cls.session.set_hand(*cls.hand.tick(dt))
            snap = cls.session.tick()
            cls._show(snap)
            if cls.panel is not None and cls.session.rebuilds:   # a part edited meanwhile
                cls.panel.show_rebuild(cls.session)
            elif cls.panel is not None:
                cls.panel.show_rebuild(None)
        except Exception as e:  # never let the timer die silently
            App.Console.PrintError("HapticGrasp: %s\n" % e)
            cls.stop()
            return
        if not cls.session.running:
            cls.stop()

    @classmethod
    def _show(cls, snap):
        """The panel, the overlay and the sounds, from the snapshot of this tick."""
        session = cls.session
        fault = snap.get("fault", "none") != "none"
        state = snap["state"]
        if cls.sounds is not None:
            was_fault = cls.last_state == "FAULT"
            cls.sounds.play(hsounds.transition_sound(cls.last_state, state, fault and not was_fault))
        cls.last_state = "FAULT" if fault else state
        if cls.panel is not None:
            cls.panel.update(session, snap, cls.sounds)
        if cls.overlay is not None:
            forces = snap.get("forces")
            if forces is not None:
                forces = tuple(App.Vector(*f) for f in forces[:2])
            rotation = None
            grasped = snap.get("grasped", -1)
            if state in hs.HOLDING and 0 <= grasped < len(snap["placements"]):
                rotation = hs.to_placement(snap["placements"][grasped]).Rotation
            more = [(App.Vector(*p), App.Vector(*f))
                    for p, f in zip(snap.get("fingertips", [])[2:], snap.get("fingertip_forces", [])[2:])]
            cls.overlay.update(state, session.hand_at(snap.get("time_s", 0.0)), forces, rotation, fault, more,
                               target=session.target)
            cls.overlay.show_clearance(snap.get("contact"))

    @classmethod
    def add_note(cls):
        """Add note (the panel's button, N): asks for a short note and puts it in the
        recording at the servo's time when N was pressed (not when the note is typed), about the part
        under the hand then."""
        session = cls.session
        if session is None or session.recording is None or not session.running:
            return
        mark = session.mark_note()   # the moment N was pressed, not when the note is typed
        from PySide import QtGui   # FreeCAD's shim
        text, ok = QtGui.QInputDialog.getText(Gui.getMainWindow(), translate("HapticGrasp", "Add note"),
                                              translate("HapticGrasp", "Note for the reviewer:"))
        if not ok or cls.session is not session or not session.running:
            return   # cancelled, or the session ended while the dialog was open
        try:
            if session.annotate(text, mark):
                App.Console.PrintMessage("HapticGrasp: note added: %s\n" % text.strip())
        except RuntimeError as e:
            App.Console.PrintError("HapticGrasp: %s\n" % e)

    @classmethod
    def cancel(cls):
        """Esc: the open manipulation is aborted (part back, no undo entry), haptics stop."""
        if cls.session is None:
            return
        if not cls.session.ready:
            cls.cancel_build()
            return
        cls.session.cancel()
        cls.stop()

    @classmethod
    def stop(cls):
        if cls.events is not None:
            _quietly(cls.events.remove)   # its view may have closed with its document
            cls.events = None
        cls.hand = None
        if cls.timer is not None:
            cls.timer.stop()
            cls.timer = None
        if cls.overlay is not None:
            _quietly(cls.overlay.remove)
            cls.overlay = None
        if cls.panel is not None:
            _quietly(lambda: cls.panel.set_running(False))   # its dialog may be closed already
        if cls.session is not None and not cls.session.ready and not cls.session.cancelled:
            cls.session.cancel_build()   # Stop while building: nothing is kept
        if cls.session is not None:
            cls.session.stop()
            if cls.panel is not None:
                _quietly(lambda: cls.panel.show_recording(cls.session))   # the final size
            cls.session = None
            App.Console.PrintMessage("HapticGrasp: stopped\n")


def _alive(widget):
    """The Qt widget behind a Python wrapper still exists (FreeCAD may delete a task
    dialog's widgets itself)."""
    try:
        import shiboken2
        return shiboken2.isValid(widget)
    except ImportError:   # Qt 6's shim: shiboken6
        import shiboken6
        return shiboken6.isValid(widget)


def _quietly(action):
    """Removes an overlay or event filter from a view that may be gone (its document was
    closed under the session), or updates a panel whose dialog may be closed (FreeCAD
    quitting): stopping must not fail for them."""
    try:
        action()
    except Exception as e:
        App.Console.PrintLog("HapticGrasp: %s\n" % e)


def _mouse_hand_for(view, target):
    """A MouseHand above `target` (outside it, in the view's up direction), grip open
    wider than the part, oriented by the view's camera."""
    from .mouse_hand import MouseHand
    rotation = view.getCameraOrientation()
    right = rotation.multVec(App.Vector(1, 0, 0))
    up = rotation.multVec(App.Vector(0, 1, 0))
    into = rotation.multVec(App.Vector(0, 0, -1))
    box = hs.global_bound_box(target)
    size = box.DiagonalLength
    return MouseHand(centre_mm=box.Center + up * (0.5 * size + 20.0), grip_mm=size + 40.0,
                     min_grip_mm=0.0, rate_mm_s=40.0, right=right, up=up, view_dir=into,
                     wrist_up_mm=100.0)


def _arm_hand_for(view, target, rest):
    """The simulated arm operator's target: a MouseHand at the arm's resting grip centre,
    its grip along the arm's grip axis, open ARM_CLEARANCE_MM outside `target`."""
    from . import mouse_hand
    rotation = view.getCameraOrientation()
    axis = App.Vector(*rest["grip_axis"])
    box = hs.global_bound_box(target)
    width = abs(axis.x) * box.XLength + abs(axis.y) * box.YLength
    return mouse_hand.for_arm(rest, width, right=rotation.multVec(App.Vector(1, 0, 0)),
                              up=rotation.multVec(App.Vector(0, 1, 0)),
                              view_dir=rotation.multVec(App.Vector(0, 0, -1)))


class MouseEvents:
    """Coin event callbacks on the 3D view feeding the controller's MouseHand: mouse motion
    moves it in the view plane, G held pinches, Esc cancels. The wheel moves it along the
    view direction through a Qt event filter on the view's viewport: in FreeCAD 0.20.2 a
    wheel event on the view never reached the scene-graph callback (the gui test saw the
    hand stay put; the navigation style zooms with it), so the filter takes the Qt wheel
    event first and consumes it (the camera does not zoom while the hand runs). Removed by
    remove() (Stop)."""

    PINCH_KEY = "G"
    MM_PER_WHEEL_STEP = 10.0

    def __init__(self, view, controller):
        from pivy import coin
        self.coin = coin
        self.view = view
        self.controller = controller
        self.last = None   # last mouse position (pixels, Coin: y up)
        self.callbacks = []
        for kind, handler in ((coin.SoLocation2Event, self._motion),
                              (coin.SoMouseButtonEvent, self._button),
                              (coin.SoKeyboardEvent, self._key)):
            type_id = kind.getClassTypeId()
            self.callbacks.append((type_id, view.addEventCallbackPivy(type_id, handler)))
        self.viewport = None
        self.wheel_filter = None
        if hasattr(view, "graphicsView"):
            self.viewport = view.graphicsView().viewport()
            self.wheel_filter = _wheel_filter(self)
            self.viewport.installEventFilter(self.wheel_filter)

    def wheel(self, notches):
        """Wheel turned away from the user (notches > 0): the hand goes into the screen."""
        hand = self.controller.hand
        if hand is not None and notches:
            hand.wheel(notches, self._camera()[2], self.MM_PER_WHEEL_STEP)

    def remove(self):
        if self.wheel_filter is not None:
            try:
                self.viewport.removeEventFilter(self.wheel_filter)
            except Exception:   # the view was closed meanwhile
                pass
            self.wheel_filter = None
            self.viewport = None
        for type_id, callback in self.callbacks:
            try:
                self.view.removeEventCallbackPivy(type_id, callback)
            except Exception:   # the view was closed meanwhile
                pass
        self.callbacks = []

    def _camera(self):
        rotation = self.view.getCameraOrientation()
        return (rotation.multVec(App.Vector(1, 0, 0)), rotation.multVec(App.Vector(0, 1, 0)),
                rotation.multVec(App.Vector(0, 0, -1)))

    def _motion(self, node):
        hand = self.controller.hand
        if hand is None:
            return
        x, y = node.getEvent().getPosition().getValue()
        if self.last is not None:
            dx, dy = x - self.last[0], y - self.last[1]
            right, up, _ = self._camera()
            # mm per pixel at the focal plane (getPoint takes Qt coordinates; the scale is the same)
            size = self.view.getSize()
            p0 = self.view.getPoint(int(x), int(size[1] - y))
            p1 = self.view.getPoint(int(x) + 1, int(size[1] - y))
            hand.move_in_view_plane(dx, dy, right, up, (p1 - p0).Length)
        self.last = (x, y)

    def _button(self, node):
        coin = self.coin
        hand = self.controller.hand
        event = node.getEvent()
        if hand is None or event.getState() != coin.SoButtonEvent.DOWN:
            return
        # A Coin without SoMouseWheelEvent sends the wheel as buttons 4 and 5 (the Qt filter
        # takes it first where it is installed).
        steps = {coin.SoMouseButtonEvent.BUTTON4: 1, coin.SoMouseButtonEvent.BUTTON5: -1}.get(event.getButton())
        if steps is not None:
            self.wheel(steps)
            node.setHandled()   # the hand moves, not the camera

    def _key(self, node):
        coin = self.coin
        event = node.getEvent()
        key = event.getKey()
        down = event.getState() == coin.SoButtonEvent.DOWN
        if key == coin.SoKeyboardEvent.ESCAPE and down:
            node.setHandled()
            from PySide import QtCore   # not from inside the callback being removed
            QtCore.QTimer.singleShot(0, self.controller.cancel)
        elif key == getattr(coin.SoKeyboardEvent, self.PINCH_KEY) and self.controller.hand is not None:
            self.controller.hand.pinch(down)
            node.setHandled()


def _wheel_filter(events):
    """A QObject whose eventFilter turns the viewport's wheel events into events.wheel()
    (angleDelta 120 = one notch) and consumes them."""
    from PySide import QtCore

    class WheelFilter(QtCore.QObject):
        def eventFilter(self, watched, event):
            if event.type() != QtCore.QEvent.Wheel or events.controller.hand is None:
                return False
            try:
                events.wheel(event.angleDelta().y() / 120.0)
            except Exception as e:   # never let an exception escape into Qt
                App.Console.PrintError("HapticGrasp: wheel: %s\n" % e)
            return True

    return WheelFilter()


class _StartCommand:
    def GetResources(self):
        return {"Pixmap": icon("HapticGrasp_Start.svg"), "Accel": ACCELS["HapticGrasp_Start"],
                "MenuText": QT_TRANSLATE_NOOP("HapticGrasp_Start", "Start haptics"),
                "ToolTip": QT_TRANSLATE_NOOP("HapticGrasp_Start",
                                             "Start the servo loop and grasp parts with the device")}

    def IsActive(self):
        return App.ActiveDocument is not None and _HapticGraspController.session is None

    def Activated(self):
        _HapticGraspController.start()


class _StopCommand:
    def GetResources(self):
        return {"Pixmap": icon("HapticGrasp_Stop.svg"), "Accel": ACCELS["HapticGrasp_Stop"],
                "MenuText": QT_TRANSLATE_NOOP("HapticGrasp_Stop", "Stop haptics"),
                "ToolTip": QT_TRANSLATE_NOOP("HapticGrasp_Stop", "Stop the servo loop")}

    def IsActive(self):
        return _HapticGraspController.session is not None

    def Activated(self):
        _HapticGraspController.stop()


class _MarkGraspableCommand:
    """Marks the selected objects graspable (HapticGraspable = True), or unmarks them when
    all are marked already. Once any part is marked, only marked parts are handed in."""

    def GetResources(self):
        return {"Pixmap": icon("HapticGrasp_MarkGraspable.svg"), "Accel": ACCELS["HapticGrasp_MarkGraspable"],
                "MenuText": QT_TRANSLATE_NOOP("HapticGrasp_MarkGraspable", "Mark graspable"),
                "ToolTip": QT_TRANSLATE_NOOP("HapticGrasp_MarkGraspable",
                                             "Mark the selected parts graspable (or unmark them); once any part is "
                                             "marked, haptics hand in only the marked parts")}

    def IsActive(self):
        return App.ActiveDocument is not None and bool(Gui.Selection.getSelection())

    def Activated(self):
        objects = [o for o in Gui.Selection.getSelection() if hs.is_part_candidate(o)]
        if not objects:
            App.Console.PrintWarning("HapticGrasp: select parts to mark (solids or PartDesign Bodies, "
                                     "not App::Part containers or Body features)\n")
            return
        on = not all(hs.is_graspable(o) for o in objects)
        doc = objects[0].Document
        doc.openTransaction(translate("HapticGrasp", "Mark graspable") if on
                            else translate("HapticGrasp", "Unmark graspable"))
        hs.set_graspable(objects, on)
        doc.commitTransaction()
        App.Console.PrintMessage("HapticGrasp: %s %s\n" % ("marked graspable:" if on else "unmarked:",
                                                            ", ".join(o.Label for o in objects)))


class _SplitSolidsCommand:
    """Splits each selected object whose shape holds several solids (a STEP assembly read
    as one compound) into one object per solid, so that each can be grasped on its own:
    one undo step; the originals are hidden, not deleted (session.split_solids)."""

    def GetResources(self):
        return {"Pixmap": icon("HapticGrasp_SplitSolids.svg"), "Accel": ACCELS["HapticGrasp_SplitSolids"],
                "MenuText": QT_TRANSLATE_NOOP("HapticGrasp_SplitSolids", "Split into solids"),
                "ToolTip": QT_TRANSLATE_NOOP("HapticGrasp_SplitSolids",
                                             "Make one object per solid of the selected objects (the originals "
                                             "are hidden), so that each solid can be grasped on its own")}

    def IsActive(self):
        return any(hs.solid_count(o) > 1 for o in Gui.Selection.getSelection())

    def Activated(self):
        selected = [o for o in Gui.Selection.getSelection() if hs.solid_count(o) > 1]
        if not selected:
            App.Console.PrintWarning("HapticGrasp: select an object whose shape holds several solids\n")
            return
        made = hs.split_solids(selected)
        App.Console.PrintMessage("HapticGrasp: split %s into %d objects, one per solid (the original hidden)\n"
                                 % (", ".join(o.Label for o in selected), len(made)))


class _ReviewCommand:
    """Review a recording: asks for a session recording (*.mcap, starting in the active
    document's recordings) and opens the Review panel to play it back on the active
    document, or on a new document built from the recording's shapes when none is open.
    Refused while a live session runs: both would move the parts and draw the hand."""

    def GetResources(self):
        return {"Pixmap": icon("HapticGrasp_Review.svg"), "Accel": ACCELS["HapticGrasp_Review"],
                "MenuText": QT_TRANSLATE_NOOP("HapticGrasp_Review", "Review a recording…"),
                "ToolTip": QT_TRANSLATE_NOOP("HapticGrasp_Review",
                                             "Play a recorded session back on the document's parts, jump to its "
                                             "events and notes, and apply the pose at any moment (one undo step)")}

    def IsActive(self):
        return True   # Activated() says why it cannot review (a live session, another panel)

    def Activated(self):
        from . import review_panel
        review_panel.run_command(_HapticGraspController)


# The workbench's commands, in toolbar and menu order: name -> class.
COMMANDS = {
    "HapticGrasp_Start": _StartCommand,
    "HapticGrasp_Stop": _StopCommand,
    "HapticGrasp_MarkGraspable": _MarkGraspableCommand,
    "HapticGrasp_SplitSolids": _SplitSolidsCommand,
    "HapticGrasp_Review": _ReviewCommand,
}
_registered = False


def register():
    """Adds the commands to FreeCAD (once); returns their names."""
    global _registered
    if not _registered:
        for name, command in COMMANDS.items():
            Gui.addCommand(name, command())
        _registered = True
    return list(COMMANDS)
