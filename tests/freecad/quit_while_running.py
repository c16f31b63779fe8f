# FreeCAD GUI script (tests/freecad/check_quit.py runs it): Start haptics on the cylinder
# document, then close FreeCAD's main window while the servo runs and a part may be held, as
# a user does; the "save changes?" box is answered Discard. FreeCAD must exit by itself.
import time

import FreeCAD as App
import FreeCADGui as Gui
from PySide import QtCore, QtGui

from freecad.hapticgrasp import TestHapticGraspGui as gui_tests
from freecad.hapticgrasp import gui as hgui

Gui.activateWorkbench("HapticGraspWorkbench")
doc, cylinder = gui_tests.cylinder_doc("QuitWhileRunning")
Gui.Selection.addSelection(cylinder)
Gui.runCommand("HapticGrasp_Start")
controller = hgui._HapticGraspController
deadline = time.monotonic() + 20
while (controller.session is None or not controller.session.running) and time.monotonic() < deadline:
    QtGui.QApplication.processEvents()
    time.sleep(0.01)
App.Console.PrintMessage("QUIT-TEST running %s\n" % (controller.session is not None and controller.session.running))


def answer_discard():
    box = QtGui.QApplication.activeModalWidget()
    if isinstance(box, QtGui.QMessageBox) and box.button(QtGui.QMessageBox.Discard) is not None:
        box.button(QtGui.QMessageBox.Discard).click()


answering = QtCore.QTimer()
answering.timeout.connect(answer_discard)
answering.start(100)
QtCore.QTimer.singleShot(700, lambda: Gui.getMainWindow().close())
