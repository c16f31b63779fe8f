"""Short sounds on grasp state transitions (QSoundEffect, WAVs in the package's sounds/
folder). Never raises: without QtMultimedia or an audio server the sounds stay silent
(QSoundEffect then never reaches Ready; we only play effects that are Ready)."""
import os

import FreeCAD as App

SOUND_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "sounds")
NAMES = ("contact", "grasp", "lift", "release", "fault")
CONTACT_STATES = ("INDEX CONTACT", "THUMB CONTACT")


def transition_sound(previous, state, fault=False):
    """The sound for a state change (None for none)."""
    if fault:
        return "fault"
    if state == previous:
        return None
    if state in CONTACT_STATES and previous not in CONTACT_STATES + ("GRASP", "MANIPULATE"):
        return "contact"
    if state == "GRASP" and previous != "MANIPULATE":
        return "grasp"
    if state == "MANIPULATE":
        return "lift"
    if previous in ("GRASP", "MANIPULATE") and state not in ("GRASP", "MANIPULATE"):
        return "release"
    return None


class SoundBoard:
    """QSoundEffects for NAMES; play(name) is a no-op for an effect that is not Ready."""

    def __init__(self, volume=0.5):
        self.effects = {}
        self.requested = []    # every play() call (name), for tests and the panel
        self.played = []       # the ones actually handed to QSoundEffect.play()
        self.error = None
        try:
            from PySide import QtCore   # FreeCAD's shim
            try:
                from PySide import QtMultimedia
            except ImportError:   # FreeCAD 0.20.2's shim has only QtCore, QtGui, QtSvg, QtUiTools
                from PySide2 import QtMultimedia
            self._ready = QtMultimedia.QSoundEffect.Status.Ready
            for name in NAMES:
                path = os.path.join(SOUND_DIR, name + ".wav")
                if not os.path.isfile(path):
                    continue
                effect = QtMultimedia.QSoundEffect()
                effect.setSource(QtCore.QUrl.fromLocalFile(path))
                effect.setVolume(volume)
                self.effects[name] = effect
        except Exception as e:  # no QtMultimedia: silent
            self.error = str(e)
            self.effects = {}

    def status(self):
        """name -> 'ready' / 'loading' / 'error' / 'null' (no audio output ⇒ never 'ready')."""
        out = {}
        for name, effect in self.effects.items():
            try:
                out[name] = str(effect.status()).split(".")[-1].lower()
            except Exception:
                out[name] = "error"
        return out

    @property
    def available(self):
        return any(s == "ready" for s in self.status().values())

    def play(self, name):
        if name is None:
            return False
        self.requested.append(name)
        effect = self.effects.get(name)
        try:
            if effect is None or effect.status() != self._ready:
                return False
            effect.play()
            self.played.append(name)
            return True
        except Exception as e:  # never let a sound break the timer
            if self.error is None:
                self.error = str(e)
                App.Console.PrintLog("HapticGrasp: sound disabled: %s\n" % e)
            return False

    def close(self):
        for effect in self.effects.values():
            try:
                effect.stop()
                effect.deleteLater()
            except Exception:
                pass
        self.effects = {}
