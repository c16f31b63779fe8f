#!/usr/bin/env python3
"""Recordings whose attached parts are hostile, made the same way on every run (seeded).

A recording carries its parts as BREP attachments (MCAP Attachment records, each with a
CRC-32 of its fields). Byte damage to the file is caught by that CRC before OCCT sees the
part; someone who means harm recomputes it. So each copy here is SOURCE with every
attachment's data replaced by a broken copy of itself (make_hostile.py's mutations) and the
record rebuilt with a correct CRC: the damage reaches the BREP reader and the checks that
`hapticgrasp replay` and `recording info` run. The summary's offsets after the first changed
record are left stale, as an edited file would have them.

Usage: hostile_recording.py OUT_DIR SOURCE.mcap   (prints the paths written, one a line)
"""
import pathlib
import random
import struct
import sys
import zlib

import make_hostile

MAGIC = b"\x89MCAP0\r\n"
ATTACHMENT = 0x09
# Mutations that keep the attachment a BREP text the reader takes in: the others (empty,
# random bytes, ...) already stand in make_hostile's copies of the whole file.
KEPT = ("truncated-mid-line", "nan", "1e308", "coordinates-nan", "coordinates-1e308", "lines-swapped",
        "counts-absurd", "indices-out-of-range")


def records(data):
    """(opcode, start, end) of each record between the leading and trailing magic."""
    at = len(MAGIC)
    while at + 9 <= len(data) - len(MAGIC):
        opcode, length = struct.unpack_from("<BQ", data, at)
        end = at + 9 + length
        if end > len(data):
            return
        yield opcode, at, end
        at = end


def string_at(body, at):
    (n,) = struct.unpack_from("<I", body, at)
    return body[at + 4 : at + 4 + n], at + 4 + n


def rebuilt_attachment(body, mutate, rng):
    """The Attachment record (opcode, length, fields, CRC) with its data mutated."""
    at = 16  # log_time, create_time
    _, at = string_at(body, at)  # name
    _, at = string_at(body, at)  # media_type
    (n,) = struct.unpack_from("<Q", body, at)
    head, payload = body[: at], body[at + 8 : at + 8 + n]
    payload = mutate(payload, rng)
    fields = head + struct.pack("<Q", len(payload)) + payload
    content = fields + struct.pack("<I", zlib.crc32(fields))
    return struct.pack("<BQ", ATTACHMENT, len(content)) + content


def make_copies(out_dir, source):
    out_dir.mkdir(parents=True, exist_ok=True)
    data = source.read_bytes()
    spans = [(start, end) for opcode, start, end in records(data) if opcode == ATTACHMENT]
    if not spans:
        sys.exit(f"hostile_recording.py: {source} has no attachment")
    written = []
    for name in KEPT:
        rng = random.Random(zlib.crc32(f"{source.name}/attachment/{name}".encode()))
        out, last = [], 0
        for start, end in spans:
            out += [data[last:start], rebuilt_attachment(data[start + 9 : end], make_hostile.MUTATIONS[name], rng)]
            last = end
        out.append(data[last:])
        target = out_dir / f"{source.stem}.attachment-{name}{source.suffix}"
        target.write_bytes(b"".join(out))
        written.append(target)
    return written


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    for path in make_copies(pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])):
        print(path)
