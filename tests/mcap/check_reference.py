#!/usr/bin/env python3
"""The reference MCAP reader (@mcap/core, via validate.mjs) on files our writer made.

    check_reference.py <mcap_sample tool> <work dir>

Writes a 3 s sample recording and an empty one with the tool, reads both with
validate.mjs and checks that the reference reader counts what the tool says it wrote
(messages per topic, attachments, metadata, chunks). Then flips one byte of a chunk's CRC
and checks that the reference reader refuses that copy (so its CRC checks do run).
Exits 77 (CTest's skip) when the npm packages are not installed (packaging/install-deps
runs `npm ci --prefix tests/mcap`) or there is no `node`.
"""
import json
import os
import shutil
import struct
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SKIP = 77


def skip(why):
    print(f"SKIP: {why}")
    sys.exit(SKIP)


def first_chunk_crc_offset(path):
    """Where the first Chunk record's uncompressed_crc field is (walking records from the magic)."""
    with open(path, "rb") as f:
        data = f.read()
    pos = 8
    while pos + 9 <= len(data):
        op, length = struct.unpack_from("<BQ", data, pos)
        if op == 0x06:
            return pos + 9 + 24
        pos += 9 + length
    raise SystemExit(f"no chunk in {path}")


def main():
    tool, work = sys.argv[1], sys.argv[2]
    if not os.path.isdir(os.path.join(HERE, "node_modules", "@mcap", "core")):
        skip("tests/mcap/node_modules is absent: run `npm ci --prefix tests/mcap` (packaging/install-deps does)")
    node = shutil.which("node")
    if node is None:
        skip("no `node` on PATH (packaging/install-deps installs nodejs)")
    os.makedirs(work, exist_ok=True)

    expected = {}
    for name, args in (("sample.mcap", []), ("empty.mcap", ["--seconds", "0"])):
        path = os.path.join(work, name)
        out = subprocess.run([tool, path, *args], check=True, capture_output=True, text=True).stdout
        expected[path] = json.loads(out)
    sample = os.path.join(work, "sample.mcap")
    if expected[sample]["chunks"] < 5 or expected[sample]["messages"] < 5000:
        raise SystemExit(f"the sample is too small to mean much: {expected[sample]}")

    run = subprocess.run([node, os.path.join(HERE, "validate.mjs"), *expected], capture_output=True, text=True)
    sys.stderr.write(run.stderr)
    if run.returncode != 0:
        raise SystemExit(f"the reference reader refused our files (exit {run.returncode})")
    got = {r["file"]: r for r in map(json.loads, run.stdout.splitlines())}
    failures = 0
    for path, want in expected.items():
        have = got.get(path, {})
        for key in ("messages", "topics", "attachments", "metadata", "chunks"):
            if have.get(key) != want[key]:
                print(f"{os.path.basename(path)}: {key}: the reference reader read {have.get(key)}, we wrote {want[key]}")
                failures += 1
        print(f"{os.path.basename(path)}: {json.dumps({k: have.get(k) for k in want if k in have})}")

    damaged = os.path.join(work, "damaged.mcap")
    shutil.copyfile(sample, damaged)
    with open(damaged, "r+b") as f:
        f.seek(first_chunk_crc_offset(damaged))
        byte = f.read(1)
        f.seek(-1, os.SEEK_CUR)
        f.write(bytes([byte[0] ^ 0x01]))
    run = subprocess.run([node, os.path.join(HERE, "validate.mjs"), damaged], capture_output=True, text=True)
    if run.returncode == 0 or "CRC" not in run.stderr:
        print(f"damaged.mcap: the reference reader did not refuse a bad chunk CRC: {run.stdout}{run.stderr}")
        failures += 1
    else:
        print(f"damaged.mcap: refused as it should be: {run.stderr.strip()}")

    if failures:
        raise SystemExit(f"{failures} disagreements with the reference reader")
    print("mcap.reference-reader: @mcap/core reads what McapWriter wrote")


if __name__ == "__main__":
    main()
