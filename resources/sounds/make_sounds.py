"""Writes the HapticGrasp state-transition sounds (tiny 16-bit mono WAVs, 22050 Hz).
Run: python3 make_sounds.py (from this folder); the outputs are committed."""
import math
import struct
import wave

RATE = 22050
SOUNDS = {  # name: [(frequency Hz, duration s), ...]
    "contact": [(1320.0, 0.04)],
    "grasp": [(880.0, 0.05), (1175.0, 0.06)],
    "lift": [(660.0, 0.04), (990.0, 0.06)],
    "release": [(990.0, 0.05), (660.0, 0.06)],
    "fault": [(220.0, 0.18)],
}


def tone(frequency, duration, volume=0.35):
    n = int(RATE * duration)
    fade = max(1, int(RATE * 0.005))
    for i in range(n):
        envelope = min(1.0, i / fade, (n - 1 - i) / fade)
        yield int(32767 * volume * envelope * math.sin(2 * math.pi * frequency * i / RATE))


for name, parts in SOUNDS.items():
    samples = [s for f, d in parts for s in tone(f, d)]
    with wave.open(name + ".wav", "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(RATE)
        w.writeframes(struct.pack("<%dh" % len(samples), *samples))
