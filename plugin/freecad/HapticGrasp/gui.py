"""GUI of the HapticGrasp workbench: Start/Stop commands and the QTimer that drives
HapticSession.tick() on the GUI thread (InitGui.py imports this from Initialize())."""
import FreeCAD as App
import FreeCADGui as Gui

from . import session as hs


class _HapticGraspController:
    """Owns the running session and the QTimer that calls its tick() (30-60 Hz)."""

    session = None
    timer = None

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
            cls.session.tick()
        except Exception as e:  # never let the timer die silently
            App.Console.PrintError("HapticGrasp: %s\n" % e)
            cls.stop()
            return
        if not cls.session.running:
            cls.stop()

    @classmethod
    def stop(cls):
        if cls.timer is not None:
            cls.timer.stop()
            cls.timer = None
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
