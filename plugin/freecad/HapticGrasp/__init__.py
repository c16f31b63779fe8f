"""HapticGrasp FreeCAD workbench: feel, grasp and move parts with a haptic device.

The compiled core is `_hapticgrasp` (next to this file); `session` is the document glue."""
