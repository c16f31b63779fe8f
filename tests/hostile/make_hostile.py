#!/usr/bin/env python3
"""Broken copies of a part file, made the same way on every run (seeded).

What a tester did by hand for issue 14: truncated, bits flipped, numbers replaced by NaN or
1e308, lines swapped, empty, zeros, random bytes; and, for BREP, section counts no file
could hold. Each copy is named SOURCE-STEM.MUTATION.EXT beside the others in OUT_DIR.

Usage: make_hostile.py OUT_DIR SOURCE_FILE...   (prints the paths written, one a line)
"""
import pathlib
import random
import re
import sys
import zlib

# A number as BREP and STEP write it; not an entity reference (#12) in STEP.
NUMBER = re.compile(rb"(?<![#\w.])-?\d+\.?\d*(?:[eE][-+]?\d+)?")
# A BREP section header: "Curves 135", "TShapes 9251".
BREP_COUNT = re.compile(rb"^(Locations|Curve2ds|Curves|Polygon3D|PolygonOnTriangulations|Surfaces|Triangulations"
                        rb"|TShapes|Polygon2D) (\d+)", re.MULTILINE)


def truncated_half(data, rng):
    return data[: len(data) // 2]


def truncated_mid_line(data, rng):
    cut = rng.randrange(len(data) * 3 // 4, len(data))
    return data[:cut]


def bits_flipped(data, rng):
    out = bytearray(data)
    for _ in range(max(1, len(data) // 2000)):
        out[rng.randrange(len(out))] ^= 1 << rng.randrange(8)
    return bytes(out)


def numbers_replaced(word):
    def mutate(data, rng):
        spans = [m.span() for m in NUMBER.finditer(data)]
        chosen = sorted(rng.sample(spans, max(1, len(spans) // 20)))
        out, last = [], 0
        for start, end in chosen:
            out += [data[last:start], word]
            last = end
        out.append(data[last:])
        return b"".join(out)
    return mutate


def coordinates_replaced(word):
    """Numbers of the geometry only (BREP: curves and surfaces past each line's type code;
    STEP: reals), so the file still reads and the damage reaches the checks."""
    def mutate(data, rng):
        if not BREP_COUNT.search(data):
            real = re.compile(rb"(?<![#\w.])-?\d+\.\d*(?:[eE][-+]?\d+)?")
            return real.sub(lambda m: word if rng.random() < 0.1 else m.group(0), data)
        lines, section = data.split(b"\n"), None
        for i, line in enumerate(lines):
            header = BREP_COUNT.match(line)
            if header:
                section = header.group(1)
            elif section in (b"Curve2ds", b"Curves", b"Surfaces") and b" " in line.strip():
                code, rest = line.split(b" ", 1)
                lines[i] = code + b" " + NUMBER.sub(lambda m: word if rng.random() < 0.1 else m.group(0), rest)
        return b"\n".join(lines)
    return mutate


def lines_swapped(data, rng):
    lines = data.split(b"\n")
    for _ in range(max(1, len(lines) // 50)):
        i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
        lines[i], lines[j] = lines[j], lines[i]
    return b"\n".join(lines)


def empty(data, rng):
    return b""


def zeros(data, rng):
    return bytes(len(data))


def random_bytes(data, rng):
    return rng.randbytes(len(data))


def counts_absurd(data, rng):
    """Every BREP section claims two billion entries (STEP: every entity number does)."""
    if BREP_COUNT.search(data):
        return BREP_COUNT.sub(lambda m: m.group(1) + b" 2000000000", data)
    return re.sub(rb"#(\d+)", lambda m: b"#" + str(2000000000 - int(m.group(1))).encode(), data)


def indices_out_of_range(data, rng):
    """Small integers (BREP's indices into its tables, STEP's references) made large."""
    if BREP_COUNT.search(data):
        small = re.compile(rb"(?<![\w.\-])([1-9]\d{0,3})(?![\w.])")
        return small.sub(lambda m: b"99999" if rng.random() < 0.05 else m.group(0), data)
    return re.sub(rb"#(\d+)(?!\s*=)", lambda m: b"#99999999" if rng.random() < 0.05 else m.group(0), data)


MUTATIONS = {
    "truncated-half": truncated_half,
    "truncated-mid-line": truncated_mid_line,
    "bits-flipped": bits_flipped,
    "bits-flipped-2": bits_flipped,
    "nan": numbers_replaced(b"nan"),
    "1e308": numbers_replaced(b"1e308"),
    "coordinates-nan": coordinates_replaced(b"nan"),
    "coordinates-1e308": coordinates_replaced(b"1e308"),
    "lines-swapped": lines_swapped,
    "lines-swapped-2": lines_swapped,
    "empty": empty,
    "zeros": zeros,
    "random-bytes": random_bytes,
    "counts-absurd": counts_absurd,
    "indices-out-of-range": indices_out_of_range,
}


def make_copies(out_dir, sources):
    """The paths written: every mutation of every source, seeded by their names."""
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    for source in sources:
        data = source.read_bytes()
        for name, mutate in MUTATIONS.items():
            rng = random.Random(zlib.crc32(f"{source.name}/{name}".encode()))
            target = out_dir / f"{source.stem}.{name}{source.suffix}"
            target.write_bytes(mutate(data, rng))
            written.append(target)
    return written


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    for path in make_copies(pathlib.Path(sys.argv[1]), map(pathlib.Path, sys.argv[2:])):
        print(path)
