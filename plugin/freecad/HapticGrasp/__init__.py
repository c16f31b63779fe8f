"""HapticGrasp FreeCAD workbench: feel, grasp and move parts with a haptic device.

An addon in FreeCAD's namespace-package layout: <Mod>/HapticGrasp/freecad/hapticgrasp/ is
imported as `freecad.hapticgrasp`; FreeCAD imports its `init` (freecadcmd and GUI) and
`init_gui` (GUI) modules at start-up. The compiled core is `_hapticgrasp`: next to this
file in the build tree's addon; installed by the Debian package, it is architecture-dependent
and lives in /usr/lib/python3/dist-packages/freecad/hapticgrasp/ while these files are in
/usr/share/freecad/Mod/HapticGrasp/ (Debian keeps compiled code out of /usr/share), so the
package's path takes in every `freecad/hapticgrasp` folder on sys.path, as FreeCAD's own
`freecad` package does. `session` is the document glue. Nothing here imports FreeCAD:
report.py runs without it."""
import os
from pkgutil import extend_path

__path__ = extend_path(__path__, __name__)

PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))
ICON_DIR = os.path.join(PACKAGE_DIR, "resources", "icons")
TRANSLATIONS_DIR = os.path.join(PACKAGE_DIR, "resources", "translations")


def icon(name):
    """The full path of the package's icon `name` (an SVG in resources/icons)."""
    return os.path.join(ICON_DIR, name)
