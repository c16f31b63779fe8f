"""The preferences page "Haptic Grasp" (Edit > Preferences): the grasp method, the force
parameters of the two-finger and the multi-finger methods (SI), and whether sessions are
recorded, stored in App.ParamGet(session.PARAMETER_PATH) and read by HapticSession.start().
Registered from init_gui.py with Gui.addPreferencePage(HapticGraspPreferences, "Haptic Grasp");
FreeCAD instantiates the class, shows `form` and calls loadSettings()/saveSettings()."""
from FreeCAD import Qt

translate = Qt.translate                   # what the user reads goes through these (FreeCAD's
QT_TRANSLATE_NOOP = Qt.QT_TRANSLATE_NOOP   # convention; pylupdate5 collects them)

# (key, label, unit, decimals, maximum, step): the two-finger method's force laws [MH] ...
FIELDS = (
    ("K_c", QT_TRANSLATE_NOOP("HapticGrasp", "Contact stiffness K_c:"), "N/m^0.5", 2, 1e7, 10.0),
    ("B_c", QT_TRANSLATE_NOOP("HapticGrasp", "Contact damping B_c:"), "N s/m^1.5", 2, 1e7, 10.0),
    ("K_g", QT_TRANSLATE_NOOP("HapticGrasp", "Grasp stiffness K_g:"), "N/m^0.5", 2, 1e7, 100.0),
    ("B_g", QT_TRANSLATE_NOOP("HapticGrasp", "Grasp damping B_g:"), "N s/m^1.5", 2, 1e7, 100.0),
    ("d_h", QT_TRANSLATE_NOOP("HapticGrasp", "Grasp hysteresis d_h:"), "m", 5, 0.1, 0.0005),
    ("K_ox", QT_TRANSLATE_NOOP("HapticGrasp", "Holding stiffness K_ox:"), "N/m", 2, 1e7, 100.0),
    ("K_oe", QT_TRANSLATE_NOOP("HapticGrasp", "Holding rotational stiffness K_oe:"), "N m/rad", 3, 1e6, 1.0),
)
# ... and the multi-finger method's springs, friction and distribution weights [RF eq 19]
# (session.PARAMETER_KEYS; gamma1 0 lets the core use 1/L^2, L the grasp's size).
MULTI_FINGER_FIELDS = (
    ("k", QT_TRANSLATE_NOOP("HapticGrasp", "Finger spring k:"), "N/m", 1, 1e7, 100.0),
    ("k_d", QT_TRANSLATE_NOOP("HapticGrasp", "Part spring k_d:"), "N/m", 1, 1e7, 100.0),
    ("mu", QT_TRANSLATE_NOOP("HapticGrasp", "Friction μ:"), "", 3, 100.0, 0.1),
    ("gamma1", QT_TRANSLATE_NOOP("HapticGrasp", "Torque weight γ1 (0: 1/L²):"), "1/m²", 3, 1e9, 1.0),
    ("gamma2", QT_TRANSLATE_NOOP("HapticGrasp", "Grasp weight γ2:"), "", 6, 1e3, 0.001),
    ("gamma3", QT_TRANSLATE_NOOP("HapticGrasp", "Regularisation γ3:"), "", 9, 1.0, 1e-6),
)


class HapticGraspPreferences:
    def __init__(self):
        from PySide import QtGui   # FreeCAD's shim: QtGui holds the widgets too
        self.form = QtGui.QWidget()
        self.form.setObjectName("HapticGraspPreferences")
        self.form.setWindowTitle(translate("HapticGrasp", "Haptic Grasp"))
        layout = QtGui.QVBoxLayout(self.form)
        methods = QtGui.QFormLayout()
        self.method = QtGui.QComboBox()
        self.method.setObjectName("HapticGrasp_Pref_Method")
        self.method.addItem(translate("HapticGrasp", "Two fingers: grasp state machine (Maekawa & Hollerbach)"),
                            "two-finger")
        self.method.addItem(translate("HapticGrasp", "Multi-finger: grasping force kept apart from the resultant "
                                                     "(every fingertip the device has)"), "multi-finger")
        methods.addRow(translate("HapticGrasp", "Grasp method:"), self.method)
        self.record = QtGui.QCheckBox(translate("HapticGrasp", "Record sessions"))
        self.record.setObjectName("HapticGrasp_Pref_Record")
        self.record.setToolTip(translate("HapticGrasp", "Start records each session for review: <document folder>/"
                                                        "<document name>.reviews/<date_time>.mcap (unsaved documents: "
                                                        "~/.local/share/HapticGrasp/reviews/). Nothing in the "
                                                        "document changes."))
        methods.addRow(self.record)
        self.contact = QtGui.QCheckBox(translate("HapticGrasp", "Carried parts meet the others"))
        self.contact.setObjectName("HapticGrasp_Pref_Contact")
        self.contact.setToolTip(translate("HapticGrasp", "A carried part stops at the other parts and slides along "
                                                         "them (exact surfaces), and the hand feels it; the panel "
                                                         "shows the clearance. Off: it passes through them."))
        methods.addRow(self.contact)
        layout.addLayout(methods)
        self.spins = {}
        self._add_group(layout, translate("HapticGrasp", "Two-finger method (SI; the paper's K_c 130, B_c 100, "
                                                         "K_g 1000, B_g 800)"), FIELDS)
        self._add_group(layout, translate("HapticGrasp", "Multi-finger method (SI; the paper's k 800, k_d 800, "
                                                         "μ 1)"), MULTI_FINGER_FIELDS)
        reset = QtGui.QPushButton(translate("HapticGrasp", "Defaults"))
        reset.setObjectName("HapticGrasp_Pref_Defaults")
        reset.clicked.connect(self.reset)
        layout.addWidget(reset)
        layout.addStretch(1)
        note = QtGui.QLabel(translate("HapticGrasp", "Read when haptics start."))
        layout.addWidget(note)

    def _add_group(self, layout, title, fields):
        """A group box of spin boxes, one per field, kept in self.spins by key."""
        from PySide import QtGui
        box = QtGui.QGroupBox(title)
        grid = QtGui.QFormLayout(box)
        for key, label, unit, decimals, maximum, step in fields:
            spin = QtGui.QDoubleSpinBox()
            spin.setObjectName("HapticGrasp_Pref_" + key)
            spin.setDecimals(decimals)
            spin.setRange(0.0, maximum)
            spin.setSingleStep(step)
            if unit:
                spin.setSuffix(" " + unit)
            grid.addRow(translate("HapticGrasp", label), spin)
            self.spins[key] = spin
        layout.addWidget(box)

    def _show(self, values):
        for key, spin in self.spins.items():
            spin.setValue(values[key])

    def _show_method(self, method):
        self.method.setCurrentIndex(max(0, self.method.findData(method)))

    def reset(self):
        from . import session as hs
        self._show(hs.default_parameters())
        self._show_method(hs.METHODS[0])
        self.record.setChecked(True)
        self.contact.setChecked(True)

    def loadSettings(self):
        from . import session as hs
        self._show(hs.stored_parameters())
        self._show_method(hs.stored_method())
        self.record.setChecked(hs.stored_record())
        self.contact.setChecked(hs.stored_contact())

    def saveSettings(self):
        from . import session as hs
        hs.store_parameters({key: spin.value() for key, spin in self.spins.items()})
        hs.store_method(self.method.currentData())
        hs.store_record(self.record.isChecked())
        hs.store_contact(self.contact.isChecked())
