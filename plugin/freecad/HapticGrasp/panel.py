"""Task panel of a haptic session (Gui.Control.showDialog): state, fingertip forces,
grasping force, servo rate and jitter, the recording, Start/Stop and Add note (N). Filled from the controller's timer tick."""
import time

from FreeCAD import Qt

translate = Qt.translate                   # what the user reads goes through these (FreeCAD's
QT_TRANSLATE_NOOP = Qt.QT_TRANSLATE_NOOP   # convention; pylupdate5 collects them)

NOT_EXPOSED = QT_TRANSLATE_NOOP("HapticGrasp", "n/a (not in the core snapshot)")

# The built-in inputs: (key, title, the core's Session method that binds the device).
DEVICES = (
    ("demo", QT_TRANSLATE_NOOP("HapticGrasp", "Demo script"), "set_hand_script"),
    ("mouse", QT_TRANSLATE_NOOP("HapticGrasp", "Mouse and keyboard"), "use_hand_input"),
    ("arm", QT_TRANSLATE_NOOP("HapticGrasp", "Simulated arm (mouse + keyboard)"), "use_simulated_arm"),
)
NO_HID = QT_TRANSLATE_NOOP("HapticGrasp", "SpaceMouse / HID: none attached")

# The read-outs: (key, label).
FIELDS = (
    ("device", QT_TRANSLATE_NOOP("HapticGrasp", "Device:")),
    ("state", QT_TRANSLATE_NOOP("HapticGrasp", "State:")),
    ("part", QT_TRANSLATE_NOOP("HapticGrasp", "Grasped part:")),
    ("index", QT_TRANSLATE_NOOP("HapticGrasp", "Index force:")),
    ("thumb", QT_TRANSLATE_NOOP("HapticGrasp", "Thumb force:")),
    ("grip", QT_TRANSLATE_NOOP("HapticGrasp", "Grasping force:")),
    ("rate", QT_TRANSLATE_NOOP("HapticGrasp", "Servo rate:")),
    ("jitter", QT_TRANSLATE_NOOP("HapticGrasp", "Servo jitter:")),
    ("time", QT_TRANSLATE_NOOP("HapticGrasp", "Servo time:")),
    ("moves", QT_TRANSLATE_NOOP("HapticGrasp", "Moves / faults:")),
    ("models", QT_TRANSLATE_NOOP("HapticGrasp", "Exact models:")),
    ("sound", QT_TRANSLATE_NOOP("HapticGrasp", "Sound:")),
    ("recording", QT_TRANSLATE_NOOP("HapticGrasp", "Recording:")),
)


def available_devices(core_session_class):
    """[(key, title, available)] of the built-in inputs."""
    return [(key, title, hasattr(core_session_class, method)) for key, title, method in DEVICES]


def hid_choices(devices):
    """[(key, title, layout file)] of the attached HID devices a back end can drive: keys
    "spacemouse:<path>" and "hid:<path>" (the controller's device)."""
    out = []
    for d in devices:
        if d["backend"] == "spacemouse":
            out.append(("spacemouse:" + d["path"], translate("HapticGrasp", "SpaceMouse %s (%s)")
                        % (d["model"], d["path"]), ""))
        elif d["backend"] == "layout":
            out.append(("hid:" + d["path"], translate("HapticGrasp", "HID: %s (%s)") % (d["model"], d["path"]),
                        d["layout"]))
    return out


def hid_message(devices, problems):
    """The panel's line about HID devices: what was found, or why nothing can be picked,
    and the problems session.list_devices() reported."""
    lines = []
    usable = hid_choices(devices)
    if not devices:
        lines.append(translate("HapticGrasp", "No SpaceMouse or HID device attached (plug one in, then reopen "
                                              "this panel)."))
    elif not usable:
        lines.append(translate("HapticGrasp", "%d HID device(s) attached, none a SpaceMouse or matched by a layout "
                                              "in <FreeCAD user data>/HapticGrasp/devices/.") % len(devices))
    lines.extend(problems)
    return "\n".join(lines)


def _vector_text(v):
    return "%.2f N  (%.2f, %.2f, %.2f)" % (v.Length, v.x, v.y, v.z)


def close_session(controller):
    """The panel's Close (the dialog's reject or accept): the same path as Esc, an open
    manipulation is cancelled (the part back where it was, no undo entry), then haptics
    stop. Nothing is committed by closing the panel."""
    if controller.session is not None:
        controller.cancel()
    else:
        controller.stop()
    controller.panel = None


class RateMeter:
    """Servo rate measured from the snapshot's tick counter against the wall clock."""

    def __init__(self, window_s=0.5):
        self.window_s = window_s
        self.mark = None
        self.rate_hz = None

    def update(self, tick, now=None):
        now = time.monotonic() if now is None else now
        if self.mark is None or tick < self.mark[0]:
            self.mark = (tick, now)
            return self.rate_hz
        dt = now - self.mark[1]
        if dt >= self.window_s:
            self.rate_hz = (tick - self.mark[0]) / dt
            self.mark = (tick, now)
        return self.rate_hz


class HapticTaskPanel:
    """The task dialog; `form` is the QWidget FreeCAD shows in the combo view."""

    def __init__(self, controller):
        from PySide import QtCore, QtGui   # FreeCAD's shim: QtGui holds the widgets too
        self.controller = controller
        self.form = QtGui.QWidget()
        self.form.setObjectName("HapticGraspTaskPanel")
        self.form.setWindowTitle("HapticGrasp")
        layout = QtGui.QVBoxLayout(self.form)
        grid = QtGui.QFormLayout()
        self.device_combo = QtGui.QComboBox()
        self.device_combo.setObjectName("HapticGrasp_DeviceCombo")
        self.device_combo.setToolTip(translate("HapticGrasp", "Mouse and keyboard: move the mouse to move the hand "
                                               "in the view plane, wheel for depth, hold G to pinch, Esc cancels. "
                                               "Simulated arm: the same keys move the target of a simulated "
                                               "operator who drives the simulated master arm; the grasp feels the "
                                               "arm's fingertips"))
        from . import session as hs
        for key, title, available in available_devices(hs.core.Session):
            title = translate("HapticGrasp", title)
            self.device_combo.addItem(title if available else translate("HapticGrasp", "%s (not available in this "
                                                                                       "build)") % title, key)
            if not available:
                self.device_combo.model().item(self.device_combo.count() - 1).setEnabled(False)
        # The HID devices actually attached (SpaceMouse, or matched by a layout).
        devices, problems = hs.list_devices()
        self.layouts = {}   # device key -> layout file
        choices = hid_choices(devices)
        for key, title, layout_file in choices:
            self.device_combo.addItem(title, key)
            self.layouts[key] = layout_file
        if not choices:
            self.device_combo.addItem(translate("HapticGrasp", NO_HID), "")
            self.device_combo.model().item(self.device_combo.count() - 1).setEnabled(False)
        current = getattr(controller, "device", "demo")
        chosen = self.device_combo.findData(current)
        if chosen < 0 and current.startswith(("spacemouse:", "hid:")):
            # Picked before, not attached now: shown as such (Start says why it cannot open).
            self.device_combo.addItem(translate("HapticGrasp", "%s (not attached)") % current.split(":", 1)[1],
                                      current)
            self.layouts[current] = getattr(controller, "device_layout", "")
            chosen = self.device_combo.count() - 1
        self.device_combo.setCurrentIndex(max(0, chosen))
        if chosen < 0:
            self._device_changed(self.device_combo.currentIndex())
        elif current in self.layouts:
            controller.device_layout = self.layouts[current]
        self.device_combo.currentIndexChanged.connect(self._device_changed)
        grid.addRow(translate("HapticGrasp", "Input:"), self.device_combo)
        self.message = QtGui.QLabel(hid_message(devices, problems))
        self.message.setObjectName("HapticGrasp_message")
        self.message.setWordWrap(True)
        self.message.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)   # the udev rule can be copied
        grid.addRow(self.message)
        self.fields = {}
        for key, title in FIELDS:
            label = QtGui.QLabel("-")
            label.setObjectName("HapticGrasp_" + key)
            grid.addRow(translate("HapticGrasp", title), label)
            self.fields[key] = label
        layout.addLayout(grid)
        buttons = QtGui.QHBoxLayout()
        self.start_button = QtGui.QPushButton(translate("HapticGrasp", "Start"))
        self.start_button.setObjectName("HapticGrasp_StartButton")
        self.stop_button = QtGui.QPushButton(translate("HapticGrasp", "Stop"))
        self.stop_button.setObjectName("HapticGrasp_StopButton")
        self.start_button.clicked.connect(self._start)
        self.stop_button.clicked.connect(self._stop)
        buttons.addWidget(self.start_button)
        buttons.addWidget(self.stop_button)
        layout.addLayout(buttons)
        self.note_button = QtGui.QPushButton(translate("HapticGrasp", "Add note"))
        self.note_button.setObjectName("HapticGrasp_NoteButton")
        self.note_button.setToolTip(translate("HapticGrasp", "A short note for the reviewer, in the recording at "
                                              "this moment, about the part under the hand (N)"))
        self.note_button.setShortcut(QtGui.QKeySequence("N"))   # a window shortcut: works over the 3D view
        self.note_button.clicked.connect(lambda: self.controller.add_note())
        layout.addWidget(self.note_button)
        self._add_build_row(layout)
        layout.addStretch(1)
        self.rate = RateMeter()
        self.set_running(False)

    # --- FreeCAD task dialog protocol -------------------------------------------------
    def getStandardButtons(self):
        from PySide import QtGui
        return int(QtGui.QDialogButtonBox.Close)

    def reject(self):
        import FreeCADGui as Gui
        close_session(self.controller)
        Gui.Control.closeDialog()
        return True

    def accept(self):
        return self.reject()

    # --- buttons ------------------------------------------------------------------------
    def _start(self):
        self.controller.start()

    def _stop(self):
        self.controller.stop()

    def device(self):
        return self.device_combo.currentData()

    def _device_changed(self, _index):
        self.controller.device = self.device()
        self.controller.device_layout = self.layouts.get(self.device(), "")

    def show_message(self, text):
        """A line under the picker (why a device could not be started, ...)."""
        self.message.setText(text)

    def set_running(self, running):
        if self.building:   # the build is over (finished or cancelled)
            self.set_building(False)
        self.device_combo.setEnabled(not running)
        self.start_button.setEnabled(not running)
        self.stop_button.setEnabled(running)
        session = getattr(self.controller, "session", None)
        self.note_button.setEnabled(running and session is not None and session.recording is not None)
        if running:
            self.rate = RateMeter()
        else:
            self.fields["state"].setText(translate("HapticGrasp", "stopped"))

    # --- model build progress ---------------------------------------------------------
    def _add_build_row(self, layout):
        """The model build: which part, a progress bar (parts done / total) and Cancel."""
        from PySide import QtGui
        self.build_label = QtGui.QLabel("")
        self.build_label.setObjectName("HapticGrasp_BuildLabel")
        self.build_bar = QtGui.QProgressBar()
        self.build_bar.setObjectName("HapticGrasp_BuildProgress")
        self.build_bar.setFormat(translate("HapticGrasp", "%v / %m parts"))
        self.cancel_button = QtGui.QPushButton(translate("HapticGrasp", "Cancel"))
        self.cancel_button.setObjectName("HapticGrasp_CancelBuildButton")
        self.cancel_button.clicked.connect(lambda: self.controller.cancel_build())
        row = QtGui.QHBoxLayout()
        row.addWidget(self.build_bar, 1)
        row.addWidget(self.cancel_button)
        layout.addWidget(self.build_label)
        layout.addLayout(row)
        self.building = False
        self.set_building(False)

    def set_building(self, building):
        """While the models are built: Start and the device choice disabled, the progress
        shown with Cancel."""
        self.building = building
        for widget in (self.build_label, self.build_bar, self.cancel_button):
            widget.setVisible(building)
        self.cancel_button.setEnabled(building)
        if building:
            self.device_combo.setEnabled(False)
            self.start_button.setEnabled(False)
            self.stop_button.setEnabled(True)
            self.fields["state"].setText(translate("HapticGrasp", "building models"))

    def show_build(self, done, total, current):
        self.build_bar.setMaximum(max(1, total))
        self.build_bar.setValue(done)
        if current:
            self.build_label.setText(translate("HapticGrasp", "Building %s (%d of %d)") % (current, done + 1, total))
        else:
            self.build_label.setText(translate("HapticGrasp", "Built %d of %d parts") % (done, total))

    def show_rebuild(self, session):
        """A part edited while running: its model being rebuilt (no Cancel: Stop stops)."""
        if session is None or not session.rebuilds:
            if not self.building and not self.build_label.isHidden():
                self.build_label.setVisible(False)
            return
        names = ", ".join(label for _build, label in session.rebuilds.values())
        self.build_label.setText(translate("HapticGrasp", "Rebuilding %s (swapped in when no part is held)") % names)
        self.build_label.setVisible(True)

    def show_recording(self, session):
        """The Recording field (also once stopped: the final size)."""
        from . import session as hs
        self.fields["recording"].setText(hs.recording_text(session.recording_status() if session else None))

    def set(self, key, text):
        self.fields[key].setText(text)

    def update(self, session, snap, sounds=None):
        f = self.fields
        fault = snap.get("fault", "none")
        f["device"].setText(session.core.device_name)
        f["state"].setText(snap["state"] + ("" if fault == "none" else "  " + translate("HapticGrasp", "(fault: %s)")
                                                                             % fault))
        grasped = snap.get("grasped", -1)
        f["part"].setText(session.parts[grasped].label if 0 <= grasped < len(session.parts) else "-")
        forces = snap.get("forces")   # not exposed by the binding yet: shown as such
        if forces is not None:
            import FreeCAD as App
            felt = getattr(session.core, "device_force_output", True)
            note = "" if felt else "  " + translate("HapticGrasp", "(not displayed: input-only device)")
            f["index"].setText(_vector_text(App.Vector(*forces[0])) + note)
            f["thumb"].setText(_vector_text(App.Vector(*forces[1])) + note)
        else:
            f["index"].setText(translate("HapticGrasp", NOT_EXPOSED))
            f["thumb"].setText(translate("HapticGrasp", NOT_EXPOSED))
        grip = snap.get("grasp_force_n")
        f["grip"].setText("%.2f N" % grip if grip is not None else translate("HapticGrasp", NOT_EXPOSED))
        rate = snap.get("rate_hz")
        if rate is None:
            measured = self.rate.update(snap.get("tick", 0))
            f["rate"].setText(translate("HapticGrasp", "%.0f Hz (ticks / wall clock)") % measured
                              if measured is not None else translate("HapticGrasp", "measuring…"))
        else:
            f["rate"].setText("%.0f Hz" % rate)
        jitter = snap.get("jitter_us")
        f["jitter"].setText("%.1f µs" % jitter if jitter is not None else translate("HapticGrasp", NOT_EXPOSED))
        f["time"].setText("%.2f s (tick %d)" % (snap.get("time_s", 0.0), snap.get("tick", 0)))
        f["moves"].setText("%d / %d" % (session.moves, snap.get("faults", 0)))
        exact, parts = snap.get("exact_parts", 0), len(session.parts)
        f["models"].setText(translate("HapticGrasp", "%d of %d parts") % (exact, parts) if exact >= parts
                            else translate("HapticGrasp", "%d of %d parts (the others felt as their boxes until "
                                                          "built)") % (exact, parts))
        self.show_recording(session)
        if sounds is not None:
            f["sound"].setText(translate("HapticGrasp", "on") if sounds.available
                               else translate("HapticGrasp", "silent (no audio output ready)"))
