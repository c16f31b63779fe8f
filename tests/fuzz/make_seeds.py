#!/usr/bin/env python3
"""Makes the fuzz targets' binary seeds (tests/fuzz/corpus): reproducible, small.

    python3 tests/fuzz/make_seeds.py <hapticgrasp> [corpus folder]

- hid_report/: report streams for fuzz_hid_report (byte 0 picks the reader: the example
  layouts sorted by name, then the SpaceMouse; then one length byte per report);
- preferences/: parameter records for fuzz_preferences (one byte the parameter, eight the
  double);
- recording/cylinder.mcap: `hapticgrasp record` for 0.05 s at 500 Hz (the project's own
  writer), and cylinder_plain.mcap, the same with its chunks stored uncompressed, CRCs 0
  and no summary, so that mutations reach the messages instead of failing the chunk's
  zstd frame or CRC (the reader accepts both: MCAP allows either).
The text seeds are copies: BREP parts from resources/parts and tests/corpus/parts, the
example HID layouts, the arm's URDF, and two STEP files FreeCAD wrote (Part.makeBox(10,
20, 5) and Part.makeCylinder(5, 10), exportStep).
"""
import os
import random
import struct
import subprocess
import sys
import tempfile

MAGIC = b"\x89MCAP0\r\n"
OP_CHUNK, OP_DATA_END, OP_FOOTER = 0x06, 0x0F, 0x02


def report(rng, report_id, size):
    data = bytearray(size)
    data[0] = report_id
    for i in range(1, size - 1, 2):
        struct.pack_into("<h", data, i, rng.randint(-300, 300))
    return bytes(data)


def stream(pick, reports):
    return bytes([pick]) + b"".join(bytes([len(r)]) + r for r in reports)


def hid_reports(folder):
    rng = random.Random(14)
    seeds = {
        "joystick": stream(0, [report(rng, 1, 10) for _ in range(3)]),
        "glove": stream(1, [report(rng, 1, 20) for _ in range(3)]),
        "spacemouse_layout": stream(2, [report(rng, 1, 13) for _ in range(3)]),
        # the SpaceMouse: translation, rotation, buttons, the newer combined report
        "spacemouse": stream(3, [report(rng, 1, 7), report(rng, 2, 7), bytes([3, 1, 0]), report(rng, 1, 13)]),
        # one short, one long, another report ID, one right
        "mixed": stream(0, [report(rng, 1, 9), report(rng, 1, 11), report(rng, 2, 10), report(rng, 1, 10)]),
    }
    write_all(folder, seeds)


def preferences(folder):
    def rec(k, v):
        return bytes([k]) + struct.pack("<d", v)
    write_all(folder, {
        "paper": b"".join(rec(k, v) for k, v in enumerate([130, 100, 1000, 800, 2e-3, 2000, 20])),
        "multi_finger": b"".join(rec(7 + k, v) for k, v in enumerate([800, 800, 1, 0, 1e-3, 1e-6])),
        "unknown": rec(13, 1.0),
    })


def write_all(folder, seeds):
    os.makedirs(folder, exist_ok=True)
    for name, data in seeds.items():
        with open(os.path.join(folder, name), "wb") as f:
            f.write(data)


def records(data):
    pos = len(MAGIC)
    while pos + 9 <= len(data):
        op, length = struct.unpack_from("<BQ", data, pos)
        yield op, data[pos + 9:pos + 9 + length]
        pos += 9 + length


def plain_chunk(content):
    """The chunk with its records uncompressed and CRC 0."""
    start, end, size, _crc = struct.unpack_from("<QQQI", content, 0)
    (n,) = struct.unpack_from("<I", content, 28)
    compression = content[32:32 + n]
    (m,) = struct.unpack_from("<Q", content, 32 + n)
    body = content[40 + n:40 + n + m]
    if compression == b"zstd":
        body = subprocess.run(["zstd", "-d", "-c"], input=body, stdout=subprocess.PIPE, check=True).stdout
    assert len(body) == size
    return struct.pack("<QQQII", start, end, size, 0, 0) + struct.pack("<Q", len(body)) + body


def plain(recording):
    out = bytearray(MAGIC)
    for op, content in records(recording):
        if op == OP_CHUNK:
            content = plain_chunk(content)
        out += struct.pack("<BQ", op, len(content)) + content
        if op == OP_DATA_END:
            break
    footer = struct.pack("<QQI", 0, 0, 0)  # no summary
    return bytes(out + struct.pack("<BQ", OP_FOOTER, len(footer)) + footer + MAGIC)


def recordings(hapticgrasp, folder):
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, "cylinder.mcap")
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([hapticgrasp, "record", "--seconds", "0.05", "--rate", "500", "-o", path],
                       cwd=tmp, stdout=subprocess.DEVNULL, check=True)
    with open(path, "rb") as f:
        data = f.read()
    with open(os.path.join(folder, "cylinder_plain.mcap"), "wb") as f:
        f.write(plain(data))


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    corpus = sys.argv[2] if len(sys.argv) == 3 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")
    hid_reports(os.path.join(corpus, "hid_report"))
    preferences(os.path.join(corpus, "preferences"))
    recordings(sys.argv[1], os.path.join(corpus, "recording"))


if __name__ == "__main__":
    main()
