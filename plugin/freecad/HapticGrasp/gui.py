"""GUI of the HapticGrasp workbench: Start/Stop commands and the QTimer that drives
HapticSession.tick() on the GUI thread (InitGui.py imports this from Initialize())."""
import FreeCAD as App
import FreeCADGui as Gui

from . import session as hs
from . import sounds as hsounds


class _HapticGraspController:
    """Owns the running session and the QTimer that calls its tick() (30-60 Hz)."""

    session = None
    timer = None
    panel = None      # the task panel (HapticTaskPanel), open while the dialog is shown
    overlay = None    # the Coin overlay (HapticOverlay), present while running
    sounds = None     # SoundBoard, created once
    last_state = "FREE"

    @classmethod
    def show_panel(cls):
        """Opens the task panel (if no other task dialog is open)."""
        if cls.panel is not None:
            return cls.panel
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
        from PySide2 import QtCore
        doc = App.ActiveDocument
        if doc is None:
            App.Console.PrintError("HapticGrasp: no active document\n")
            return
        cls.stop()
        session = hs.HapticSession(doc)
        if not session.objects:
            App.Console.PrintError("HapticGrasp: no visible solid to grasp\n")
            return
        # The only device bound so far: a scripted demo hand grasping the selected part
        # (or the first solid), lifting it, carrying it 100 mm along y, putting it down.
        selected = [o for o in Gui.Selection.getSelection() if o in session.objects]
        target = selected[0] if selected else session.objects[0]
        keys, frame = hs.demo_script(target)
        session.use_hand_script(keys, frame)
        session.start()
        cls.session = session
        cls.last_state = "FREE"
        if cls.sounds is None:
            cls.sounds = hsounds.SoundBoard()
        cls.show_panel()
        if cls.panel is not None:
            cls.panel.set_running(True)
        view = getattr(Gui.ActiveDocument, "ActiveView", None) if Gui.ActiveDocument else None
        if view is not None and hasattr(view, "getSceneGraph"):
            try:
                from . import overlay as hoverlay
                cls.overlay = hoverlay.HapticOverlay(view)
            except Exception as e:  # no pivy: run without the overlay
                App.Console.PrintWarning("HapticGrasp: no 3D overlay: %s\n" % e)
                cls.overlay = None
        cls.timer = QtCore.QTimer()
        cls.timer.setInterval(20)  # 50 Hz
        cls.timer.timeout.connect(cls.tick)
        cls.timer.start()
        App.Console.PrintMessage("HapticGrasp: started with %d part(s)\n" % len(session.objects))

    @classmethod
    def tick(cls):
        if cls.session is None:
            return
        try:
            snap = cls.session.tick()
            cls._show(snap)
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
            cls.overlay.update(state, session.hand_at(snap.get("time_s", 0.0)), forces, rotation, fault)

    @classmethod
    def stop(cls):
        if cls.timer is not None:
            cls.timer.stop()
            cls.timer = None
        if cls.overlay is not None:
            try:
                cls.overlay.remove()
            finally:
                cls.overlay = None
        if cls.panel is not None:
            cls.panel.set_running(False)
        if cls.session is not None:
            cls.session.stop()
            cls.session = None
            App.Console.PrintMessage("HapticGrasp: stopped\n")


class _StartCommand:
    def GetResources(self):
        return {"MenuText": "Start haptics", "ToolTip": "Start the servo loop and grasp parts with the device"}

    def IsActive(self):
        return App.ActiveDocument is not None and _HapticGraspController.session is None

    def Activated(self):
        _HapticGraspController.start()


class _StopCommand:
    def GetResources(self):
        return {"MenuText": "Stop haptics", "ToolTip": "Stop the servo loop"}

    def IsActive(self):
        return _HapticGraspController.session is not None

    def Activated(self):
        _HapticGraspController.stop()



_registered = False


def register():
    global _registered
    if not _registered:
        Gui.addCommand("HapticGrasp_Start", _StartCommand())
        Gui.addCommand("HapticGrasp_Stop", _StopCommand())
        _registered = True
    return ["HapticGrasp_Start", "HapticGrasp_Stop"]
