"""The Review panel (Gui.Control.showDialog): plays a recorded session back on the document.

At the top the file and the warnings (parts missing, changed or extra; a recording cut
short); below, a timeline (slider, time, play/pause, one frame back and forward, speed,
loop), the events and notes to jump to, the recorded state and forces at the cursor, and
"Apply the pose at the cursor". Playing back moves only the parts' view providers and draws
the hand and the forces with the live session's overlay (review.Review.preview): no undo
entry, the document not marked modified. Apply is one undo step. Closing the panel puts
every view provider back where the document has its part and removes the overlay.

The widgets keep to the combo view's width: short buttons with icons, labels that wrap.
"""
import os
import time

import FreeCAD as App
import FreeCADGui as Gui
from FreeCAD import Qt

translate = Qt.translate   # FreeCAD's convention; pylupdate5 collects the ("HapticGrasp", text) calls

from . import review as hreview
from . import session as hs

SPEEDS = (0.25, 0.5, 1.0, 2.0, 4.0)
TICK_MS = 30   # the playback timer: about 33 frames a second, as many as the GUI draws anyway
_current = None   # the open ReviewPanel (one at a time, as Gui.Control allows)


def current():
    """The open Review panel, or None."""
    return _current


def open_review(path, doc=None):
    """Opens the Review panel on the recording `path`, played back on `doc` (its parts
    matched by name and compared by content) or, with doc None, on a new document built
    from the shapes the recording carries. Returns the panel; raises RuntimeError (a file
    that is not a recording, another task dialog open)."""
    global _current
    if Gui.Control.activeDialog():
        raise RuntimeError(translate("HapticGrasp", "Another task panel is open: close it before reviewing a "
                                                    "recording."))
    review = hreview.Review(path, doc) if doc is not None else hreview.open_without_document(path)
    panel = ReviewPanel(review)
    Gui.Control.showDialog(panel)
    _current = panel
    panel.seek(0.0)
    return panel


def start_folder(doc):
    """Where the file dialog starts: the document's recordings (<name>.reviews beside it,
    or the unsaved documents' folder), else the document's folder, else the home folder."""
    folder = hreview.reviews_folder(doc)
    if os.path.isdir(folder):
        return folder
    if doc is not None and doc.FileName:
        return os.path.dirname(doc.FileName)
    return os.path.expanduser("~")


def run_command(controller):
    """The Review command: refuses while a live haptic session runs (both would move the
    parts and draw the hand), asks for a recording and opens it against the active
    document, or on a new document when none is open. Returns the panel or None."""
    from PySide import QtCore, QtGui   # FreeCAD's shim
    window = Gui.getMainWindow()
    title = translate("HapticGrasp", "Review a recording")
    if controller.session is not None:
        QtGui.QMessageBox.warning(window, title, translate("HapticGrasp", "A haptic session is running: stop it "
                                                                          "before reviewing a recording."))
        return None
    if Gui.Control.activeDialog():
        QtGui.QMessageBox.warning(window, title, translate("HapticGrasp", "Another task panel is open: close it "
                                                                          "before reviewing a recording."))
        return None
    doc = App.ActiveDocument
    path, _filter = QtGui.QFileDialog.getOpenFileName(window, title, start_folder(doc),
                                                      translate("HapticGrasp", "Session recordings (*.mcap)"))
    if not path:
        return None
    # One pass over the file (measured in FreeCAD: 3 s for 10 minutes at 2 kHz, 11 s at 8 kHz): say so.
    QtGui.QApplication.setOverrideCursor(QtCore.Qt.WaitCursor)
    try:
        return open_review(path, doc)
    except RuntimeError as e:
        error = str(e)
    finally:
        QtGui.QApplication.restoreOverrideCursor()
    App.Console.PrintError("HapticGrasp: %s\n" % error)
    QtGui.QMessageBox.critical(window, title, error)
    return None


def _vector(v):
    return App.Vector(*v)


class ReviewPanel:
    """The task dialog; `form` is the QWidget the combo view shows; `review` the model."""

    def __init__(self, review):
        from PySide import QtCore, QtGui   # FreeCAD's shim: QtGui holds the widgets too
        self.review = review
        self.t = 0.0
        self.playing = False
        self._clock = None   # monotonic time of the last playback tick
        self.overlay = None
        self.closed = False
        self.form = QtGui.QWidget()
        self.form.setObjectName("HapticGrasp_ReviewPanel")
        self.form.setWindowTitle(translate("HapticGrasp", "Review"))
        layout = QtGui.QVBoxLayout(self.form)

        name = os.path.basename(review.path)
        self.file_label = QtGui.QLabel("<b>%s</b>" % name)
        self.file_label.setObjectName("HapticGrasp_ReviewFile")
        self.file_label.setToolTip(review.path)
        self.file_label.setWordWrap(True)
        layout.addWidget(self.file_label)
        self.about_label = QtGui.QLabel(self._about())
        self.about_label.setObjectName("HapticGrasp_ReviewAbout")
        self.about_label.setWordWrap(True)
        layout.addWidget(self.about_label)
        self.warnings_label = QtGui.QLabel("")
        self.warnings_label.setObjectName("HapticGrasp_ReviewWarnings")
        self.warnings_label.setWordWrap(True)
        self.warnings_label.setStyleSheet("color: #c00000;")
        self.warnings_label.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)
        layout.addWidget(self.warnings_label)

        # The timeline: milliseconds on the slider.
        self.slider = QtGui.QSlider(QtCore.Qt.Horizontal)
        self.slider.setObjectName("HapticGrasp_ReviewSlider")
        self.slider.setRange(0, max(1, int(round(review.duration_s * 1000))))
        self.slider.setSingleStep(10)
        self.slider.setPageStep(1000)
        self.slider.valueChanged.connect(self._slider_moved)
        layout.addWidget(self.slider)
        self.time_label = QtGui.QLabel("")
        self.time_label.setObjectName("HapticGrasp_ReviewTime")
        layout.addWidget(self.time_label)

        style = self.form.style()
        row = QtGui.QHBoxLayout()
        self.back_button = self._button("HapticGrasp_ReviewStepBack", style.standardIcon(
            QtGui.QStyle.SP_MediaSeekBackward), translate("HapticGrasp", "One frame back"), lambda: self.step(-1))
        self.play_button = self._button("HapticGrasp_ReviewPlay", style.standardIcon(QtGui.QStyle.SP_MediaPlay),
                                        translate("HapticGrasp", "Play / pause"), self.toggle_play)
        self.play_button.setText(translate("HapticGrasp", "Play"))
        self.forward_button = self._button("HapticGrasp_ReviewStepForward", style.standardIcon(
            QtGui.QStyle.SP_MediaSeekForward), translate("HapticGrasp", "One frame forward"), lambda: self.step(1))
        for button in (self.back_button, self.play_button, self.forward_button):
            row.addWidget(button)
        layout.addLayout(row)
        row = QtGui.QHBoxLayout()
        row.addWidget(QtGui.QLabel(translate("HapticGrasp", "Speed:")))
        self.speed_combo = QtGui.QComboBox()
        self.speed_combo.setObjectName("HapticGrasp_ReviewSpeed")
        for speed in SPEEDS:
            self.speed_combo.addItem(("%g" % speed) + "×", speed)
        self.speed_combo.setCurrentIndex(SPEEDS.index(1.0))
        row.addWidget(self.speed_combo)
        self.loop_box = QtGui.QCheckBox(translate("HapticGrasp", "Loop"))
        self.loop_box.setObjectName("HapticGrasp_ReviewLoop")
        row.addWidget(self.loop_box)
        row.addStretch(1)
        layout.addLayout(row)

        self.state_label = QtGui.QLabel("")
        self.state_label.setObjectName("HapticGrasp_ReviewState")
        self.state_label.setWordWrap(True)
        layout.addWidget(self.state_label)

        events_label = QtGui.QLabel(translate("HapticGrasp", "Events and notes (click to jump there):"))
        events_label.setWordWrap(True)
        layout.addWidget(events_label)
        self.events_list = QtGui.QListWidget()
        self.events_list.setObjectName("HapticGrasp_ReviewEvents")
        self.events_list.setWordWrap(True)
        self.events_list.setMinimumHeight(100)
        for t, text, kind in review.timeline():
            prefix = {"note": translate("HapticGrasp", "note:") + " ",
                      "fault": translate("HapticGrasp", "fault:") + " "}.get(kind, "")
            item = QtGui.QListWidgetItem("%.2f s  %s%s" % (t, prefix, text))
            item.setData(QtCore.Qt.UserRole, float(t))
            if kind == "fault":
                item.setForeground(QtGui.QBrush(QtGui.QColor(200, 0, 0)))
            elif kind == "note":
                item.setForeground(QtGui.QBrush(QtGui.QColor(0, 90, 200)))
            self.events_list.addItem(item)
        self.events_list.itemClicked.connect(self._jump)
        self.events_list.itemActivated.connect(self._jump)
        layout.addWidget(self.events_list, 1)

        self.apply_button = QtGui.QPushButton(translate("HapticGrasp", "Apply the pose at the cursor"))
        self.apply_button.setObjectName("HapticGrasp_ReviewApply")
        self.apply_button.setToolTip(translate("HapticGrasp", "Set the parts where the recording has them at the "
                                                              "cursor (one undo step)"))
        self.apply_button.clicked.connect(self.apply)
        self.apply_button.setEnabled(review.doc is not None)
        layout.addWidget(self.apply_button)
        self.message = QtGui.QLabel("")
        self.message.setObjectName("HapticGrasp_ReviewMessage")
        self.message.setWordWrap(True)
        layout.addWidget(self.message)

        self.timer = QtCore.QTimer(self.form)   # owned by the form: stops with it
        self.timer.setInterval(TICK_MS)
        self.timer.timeout.connect(self._tick)
        self._make_overlay()
        self.show_warnings()

    def _button(self, name, icon, tip, slot):
        from PySide import QtGui
        button = QtGui.QPushButton()
        button.setObjectName(name)
        button.setIcon(icon)
        button.setToolTip(tip)
        button.clicked.connect(slot)
        return button

    def _about(self):
        info = self.review.info
        lines = [translate("HapticGrasp", "%.2f s, %d part(s), %d moved")
                 % (self.review.duration_s, len(self.review.parts), len(self.review.moved))]
        document = info.get("document") or ""
        if document:
            lines.append(translate("HapticGrasp", "Recorded on %s") % os.path.basename(document))
        if self.review.doc is not None:
            lines.append(translate("HapticGrasp", "Played back on %s") % self.review.doc.Label)
        return "\n".join(lines)

    def _make_overlay(self):
        """The live session's overlay (hand, forces, grasp frame) in the document's view."""
        doc = self.review.doc
        gui_doc = Gui.getDocument(doc.Name) if doc is not None else None
        view = getattr(gui_doc, "ActiveView", None) if gui_doc is not None else None
        if view is None or not hasattr(view, "getSceneGraph"):
            return
        try:
            from . import overlay as hoverlay
            self.overlay = hoverlay.HapticOverlay(view)
        except Exception as e:   # no pivy: the parts still move
            App.Console.PrintWarning("HapticGrasp: no 3D overlay in the review: %s\n" % e)
            self.overlay = None

    def show_warnings(self):
        lines = list(self.review.recording_warnings) + list(self.review.warnings)
        self._warning_count = len(lines)
        self.warnings_label.setText("\n".join(lines))
        self.warnings_label.setVisible(bool(lines))

    # --- FreeCAD task dialog protocol -------------------------------------------------
    def getStandardButtons(self):
        from PySide import QtGui
        return int(QtGui.QDialogButtonBox.Close)

    def reject(self):
        self.finish()
        Gui.Control.closeDialog()
        return True

    def accept(self):
        return self.reject()

    def finish(self):
        """Stops playback, puts the view providers back where the document has the parts
        and removes the overlay. Safe to call twice."""
        global _current
        if self.closed:
            return
        self.closed = True
        self.timer.stop()
        self.playing = False
        try:
            self.review.restore()
        finally:
            if self.overlay is not None:
                try:
                    self.overlay.remove()
                except Exception:   # the view was closed meanwhile
                    pass
                self.overlay = None
            if _current is self:
                _current = None

    # --- the cursor ---------------------------------------------------------------------
    def seek(self, t):
        """Moves the cursor to t (s, clamped to the recording): the parts, the hand, the
        forces and the labels as recorded then."""
        if self.closed:
            return
        t = min(max(0.0, float(t)), self.review.duration_s)
        self.t = t
        try:
            frame = self.review.frame(t)
            self.review.preview(t)
            self._draw(frame, t)
        except Exception as e:   # a document closed or edited away meanwhile: say it, stop playing
            self.pause()
            self.message.setText(translate("HapticGrasp", "Cannot show %.2f s: %s") % (t, e))
            App.Console.PrintError("HapticGrasp: review: %s\n" % e)
            return
        self.slider.blockSignals(True)
        self.slider.setValue(int(round(t * 1000)))
        self.slider.blockSignals(False)
        self.time_label.setText("%.2f / %.2f s" % (t, self.review.duration_s))
        self._show_state(frame)
        if len(self.review.recording_warnings) + len(self.review.warnings) != self._warning_count:
            self.show_warnings()   # preview() found a part it cannot move

    def _draw(self, frame, t):
        if self.overlay is None:
            return
        hand = tuple(_vector(p) for p in frame["hand"])
        forces = tuple(_vector(f) for f in frame["forces"])
        more = [(_vector(p), _vector(f)) for p, f in zip(frame["fingertips"][2:], frame["fingertip_forces"][2:])]
        self.overlay.update(frame["state"], hand, forces, self.review.grasped_rotation(t, frame), frame["fault"],
                            more)

    def _show_state(self, frame):
        state = frame["state"]
        if frame["fault"]:
            state += "  " + translate("HapticGrasp", "(device fault)")
        part = self.review.part_name(frame["grasped"])
        if part and frame["state"] in hs.HOLDING:
            state += "  " + (translate("HapticGrasp", "holding %s") % part)
        forces = [_vector(f).Length for f in frame["fingertip_forces"]] or [_vector(f).Length
                                                                             for f in frame["forces"]]
        forces_text = translate("HapticGrasp", "Fingertip forces %s N, grasping force %.2f N") % (
            ", ".join("%.2f" % f for f in forces), frame["grasp_force_n"])
        self.state_label.setText("%s\n%s" % (state, forces_text))

    def _slider_moved(self, value):
        self.seek(value / 1000.0)

    def _jump(self, item):
        from PySide import QtCore
        self.pause()
        self.seek(item.data(QtCore.Qt.UserRole))

    def step(self, direction):
        """One frame forward (direction 1) or back (-1); pauses playback."""
        self.pause()
        self.seek(self.review.step(self.t, direction))

    # --- playback -----------------------------------------------------------------------
    def speed(self):
        return self.speed_combo.currentData() or 1.0

    def play(self):
        if self.closed:
            return
        if self.t >= self.review.duration_s - 1e-9:
            self.seek(0.0)   # at the end: play again from the start
        self.playing = True
        self._clock = time.monotonic()
        self.play_button.setText(translate("HapticGrasp", "Pause"))
        self.play_button.setIcon(self.form.style().standardIcon(self._style_icon("SP_MediaPause")))
        self.timer.start()

    def pause(self):
        self.playing = False
        self.timer.stop()
        self.play_button.setText(translate("HapticGrasp", "Play"))
        self.play_button.setIcon(self.form.style().standardIcon(self._style_icon("SP_MediaPlay")))

    @staticmethod
    def _style_icon(name):
        from PySide import QtGui
        return getattr(QtGui.QStyle, name)

    def toggle_play(self):
        if self.playing:
            self.pause()
        else:
            self.play()

    def _tick(self):
        """Playback: the cursor advances by the wall time since the last tick times the
        speed; at the end it loops or stops."""
        if not self.playing or self.closed:
            return
        now = time.monotonic()
        t = self.t + (now - self._clock) * self.speed()
        self._clock = now
        end = self.review.duration_s
        if t >= end:
            if self.loop_box.isChecked() and end > 0:
                t = t % end
            else:
                self.seek(end)
                self.pause()
                return
        self.seek(t)

    # --- apply --------------------------------------------------------------------------
    def apply(self):
        """Sets the parts where the recording has them at the cursor: one undo step."""
        self.pause()
        try:
            written = self.review.apply(self.t)
        except Exception as e:
            self.message.setText(translate("HapticGrasp", "Cannot apply the pose: %s") % e)
            App.Console.PrintError("HapticGrasp: review: cannot apply the pose: %s\n" % e)
            return []
        self.review.preview(self.t)   # what the view shows is now the document's
        if written:
            text = translate("HapticGrasp", "Applied the pose at %.2f s to %s (one undo step).") % (
                self.t, ", ".join(written))
            App.Console.PrintMessage("HapticGrasp: %s\n" % text)
        else:
            text = translate("HapticGrasp", "The parts already stand where the recording has them at %.2f s: "
                                            "nothing applied.") % self.t
        self.message.setText(text)
        return written
