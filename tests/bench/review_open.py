#!/usr/bin/env python3
"""How long the Review panel takes to open a recording, and to seek in it: times
core.open_review (one streaming pass over the file) and 1,000 seeks (the frame at t and
every moved part's placement), and prints the process's peak resident memory. Prints
figures, asserts nothing.

Usage: python3 tests/bench/review_open.py build/freecad/HapticGrasp/freecad/hapticgrasp FILE.mcap [...]"""
import os
import resource
import sys
import time


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    sys.path.insert(0, sys.argv[1])
    import _hapticgrasp as core
    for path in sys.argv[2:]:
        start = time.monotonic()
        track = core.open_review(path)
        opened = time.monotonic() - start
        start = time.monotonic()
        for k in range(1000):
            t = track.duration_s * k / 1000.0
            track.placements_at(t)
            track.frame(track.frame_at(t))
        seek = (time.monotonic() - start) / 1000.0
        print("%s: %.1f MB, %.1f s recorded, %d frames, %d events: open %.2f s, a seek %.1f us, peak RSS %.0f MB"
              % (os.path.basename(path), os.path.getsize(path) / 1e6, track.duration_s, track.frame_count,
                 len(track.events), opened, seek * 1e6, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024))


if __name__ == "__main__":
    main()
