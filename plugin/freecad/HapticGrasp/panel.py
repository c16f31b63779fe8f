"""Task panel of a haptic session (Gui.Control.showDialog): state, fingertip forces,
grasping force, servo rate, period error and real time, the recording, Start/Stop and Add note (N). Filled from the controller's timer tick."""
import os
import time

from FreeCAD import Qt

translate = Qt.translate                   # what the user reads goes through these (FreeCAD's
QT_TRANSLATE_NOOP = Qt.QT_TRANSLATE_NOOP   # convention; pylupdate5 collects them)

NOT_EXPOSED = QT_TRANSLATE_NOOP("HapticGrasp", "n/a (not in the core snapshot)")

# The built-in inputs: (key, title, the core's Session method that binds the device).
DEVICES = (
    ("demo", QT_TRANSLATE_NOOP("HapticGrasp", "Demo script"), "set_hand_script"),
    ("mouse", QT_TRANSLATE_NOOP("HapticGrasp", "Mouse and keyboard"), "use_hand_input"),
    ("arm", QT_TRANSLATE_NOOP("HapticGrasp", "Simulated arm"), "use_simulated_arm"),
)
NO_HID = QT_TRANSLATE_NOOP("HapticGrasp", "No SpaceMouse / HID")

# The read-outs: (key, label).
FIELDS = (
    ("device", QT_TRANSLATE_NOOP("HapticGrasp", "Device:")),
    ("state", QT_TRANSLATE_NOOP("HapticGrasp", "State:")),
    ("part", QT_TRANSLATE_NOOP("HapticGrasp", "Grasped part:")),
    ("index", QT_TRANSLATE_NOOP("HapticGrasp", "Index force:")),
    ("thumb", QT_TRANSLATE_NOOP("HapticGrasp", "Thumb force:")),
    ("grip", QT_TRANSLATE_NOOP("HapticGrasp", "Grasping force:")),
    ("clearance", QT_TRANSLATE_NOOP("HapticGrasp", "Clearance:")),
    ("rate", QT_TRANSLATE_NOOP("HapticGrasp", "Servo rate:")),
    ("jitter", QT_TRANSLATE_NOOP("HapticGrasp", "Period error p99:")),
    ("realtime", QT_TRANSLATE_NOOP("HapticGrasp", "Real time:")),
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
    "spacemouse:<path>" and "hid:<path>" (the controller's device); titles short enough for
    the picker: the model and the device node's name."""
    out = []
    for d in devices:
        title = "%s (%s)" % (d["model"], os.path.basename(d["path"]))
        if d["backend"] == "spacemouse":
            out.append(("spacemouse:" + d["path"], title, ""))
        elif d["backend"] == "layout":
            out.append(("hid:" + d["path"], title, d["layout"]))
    return out


def hid_tip(key, layout_file):
    """A HID device's tool tip in the picker: what drives it and its device node."""
    kind, path = key.split(":", 1)
    if kind == "spacemouse":
        return translate("HapticGrasp", "SpaceMouse, %s") % path
    return translate("HapticGrasp", "HID layout %s, %s") % (os.path.basename(layout_file), path)


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
    return "(%.2f, %.2f, %.2f) N" % (v.x, v.y, v.z)


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
        from PySide import QtGui   # FreeCAD's shim: QtGui holds the widgets too
        self.controller = controller
        self.form = QtGui.QWidget()
        self.form.setObjectName("HapticGraspTaskPanel")
        self.form.setWindowTitle("HapticGrasp")
        # Narrow enough for the combo view's default width (264 px): the picker gets a row of
        # its own, texts that can be long wrap, and the recording gets the full width.
        layout = QtGui.QVBoxLayout(self.form)
        self._add_device_picker(layout)
        self._add_readouts(layout)
        self._add_buttons(layout)
        self._add_build_row(layout)
        layout.addStretch(1)
        self.rate = RateMeter()
        self.set_running(False)

    def _add_device_picker(self, layout):
        """Input: the built-in inputs and the attached HID devices, and a line about them."""
        from PySide import QtCore, QtGui
        from . import session as hs
        layout.addWidget(QtGui.QLabel(translate("HapticGrasp", "Input:")))
        self.device_combo = QtGui.QComboBox()
        self.device_combo.setObjectName("HapticGrasp_DeviceCombo")
        self.device_combo.setToolTip(translate("HapticGrasp", "Mouse and keyboard: move the mouse to move the hand "
                                               "in the view plane, wheel for depth, hold G to pinch, Esc cancels. "
                                               "Simulated arm: the same keys move the target of a simulated "
                                               "operator who drives the simulated master arm; the grasp feels the "
                                               "arm's fingertips"))
        # A long device name does not widen the panel: the picker shows what fits, the
        # item's tool tip the whole name.
        self.device_combo.setSizeAdjustPolicy(QtGui.QComboBox.AdjustToMinimumContentsLengthWithIcon)
        self.device_combo.setMinimumContentsLength(12)
        for key, title, available in available_devices(hs.core.Session):
            title = translate("HapticGrasp", title)
            self._add_device(title if available else translate("HapticGrasp", "%s (unavailable)") % title, key,
                             enabled=available)
        devices, problems = hs.list_devices()   # attached: a SpaceMouse, or matched by a layout
        self.layouts = {}   # device key -> layout file
        choices = hid_choices(devices)
        for key, title, layout_file in choices:
            self._add_device(title, key, tip=hid_tip(key, layout_file))
            self.layouts[key] = layout_file
        if not choices:
            self._add_device(translate("HapticGrasp", NO_HID), "", enabled=False)
        self._pick(getattr(self.controller, "device", "demo"))
        self.device_combo.currentIndexChanged.connect(self._device_changed)
        layout.addWidget(self.device_combo)
        self.message = QtGui.QLabel(hid_message(devices, problems))
        self.message.setObjectName("HapticGrasp_message")
        self.message.setWordWrap(True)
        self.message.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)   # the udev rule can be copied
        layout.addWidget(self.message)

    def _add_device(self, title, key, enabled=True, tip=None):
        from PySide import QtCore
        self.device_combo.addItem(title, key)
        row = self.device_combo.count() - 1
        self.device_combo.setItemData(row, tip or title, QtCore.Qt.ToolTipRole)
        self.device_combo.model().item(row).setEnabled(enabled)

    def _pick(self, current):
        """Selects the controller's device; one picked before and not attached now is shown
        as such (Start says why it cannot open)."""
        chosen = self.device_combo.findData(current)
        if chosen < 0 and current.startswith(("spacemouse:", "hid:")):
            self._add_device(translate("HapticGrasp", "%s (not attached)") % current.split(":", 1)[1], current)
            self.layouts[current] = getattr(self.controller, "device_layout", "")
            chosen = self.device_combo.count() - 1
        self.device_combo.setCurrentIndex(max(0, chosen))
        if chosen < 0:
            self._device_changed(self.device_combo.currentIndex())
        elif current in self.layouts:
            self.controller.device_layout = self.layouts[current]

    def _add_readouts(self, layout):
        """The read-outs (label: value, values wrap); the recording below at full width."""
        from PySide import QtGui
        grid = QtGui.QFormLayout()
        self.fields = {}
        for key, title in FIELDS:
            label = QtGui.QLabel("-")
            label.setObjectName("HapticGrasp_" + key)
            label.setWordWrap(True)
            self.fields[key] = label
            if key == "recording":   # a file name: wider than the value column
                grid.addRow(QtGui.QLabel(translate("HapticGrasp", title)))
                grid.addRow(label)
            else:
                grid.addRow(translate("HapticGrasp", title), label)
        layout.addLayout(grid)

    def _add_buttons(self, layout):
        """Start and Stop (with the commands' icons), Add note (N)."""
        from PySide import QtGui
        from . import icon
        buttons = QtGui.QHBoxLayout()
        self.start_button = QtGui.QPushButton(QtGui.QIcon(icon("HapticGrasp_Start.svg")),
                                              translate("HapticGrasp", "Start"))
        self.start_button.setObjectName("HapticGrasp_StartButton")
        self.stop_button = QtGui.QPushButton(QtGui.QIcon(icon("HapticGrasp_Stop.svg")),
                                             translate("HapticGrasp", "Stop"))
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
        self.build_label.setWordWrap(True)
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

    def show_realtime(self, timing):
        """The Real time field: what the servo thread asked for and got; refused, the why and
        the fix in the tool tip (and in the report view, said once at Start)."""
        field = self.fields["realtime"]
        if timing["realtime"]:
            text = (translate("HapticGrasp", "SCHED_FIFO, memory locked") if timing["memory_lock"] == "mlockall"
                    else translate("HapticGrasp", "SCHED_FIFO, memory not locked"))
            tip = timing["memory_lock"]
        elif timing["advice"]:
            text = translate("HapticGrasp", "refused: the rate may suffer (tool tip, report view)")
            tip = timing["advice"]
        else:
            text = translate("HapticGrasp", "not asked for (preferences)")
            tip = timing["scheduler"]
        if field.text() != text:
            field.setText(text)
            field.setToolTip(tip)

    def set(self, key, text):
        self.fields[key].setText(text)

    def update(self, session, snap, sounds=None):
        from . import session as hs
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
            for key, force in (("index", App.Vector(*forces[0])), ("thumb", App.Vector(*forces[1]))):
                f[key].setText("%.2f N" % force.Length + note)   # the direction: the tool tip, the 3D view
                f[key].setToolTip(_vector_text(force))
        else:
            f["index"].setText(translate("HapticGrasp", NOT_EXPOSED))
            f["thumb"].setText(translate("HapticGrasp", NOT_EXPOSED))
        grip = snap.get("grasp_force_n")
        f["grip"].setText("%.2f N" % grip if grip is not None else translate("HapticGrasp", NOT_EXPOSED))
        contact = snap.get("contact")
        text = hs.contact_text(contact, [p.label for p in session.parts])
        if not getattr(session.core, "contact", True):
            text += "  " + translate("HapticGrasp", "(contact off: parts pass through)")
        f["clearance"].setText(text)
        rate = snap.get("rate_hz")
        if rate is None:
            measured = self.rate.update(snap.get("tick", 0))
            f["rate"].setText(translate("HapticGrasp", "%.0f Hz (measured)") % measured
                              if measured is not None else translate("HapticGrasp", "measuring…"))
        else:
            f["rate"].setText("%.0f Hz" % rate)
        jitter = snap.get("jitter_us")
        f["jitter"].setText("%.1f µs" % jitter if jitter is not None else translate("HapticGrasp", NOT_EXPOSED))
        self.show_realtime(session.servo_timing())
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
