"""How long, and how much memory, refusing a zip of millions of entries takes (issue 32).

Usage (from the repository root):

    python scripts/archive_refusal_figures.py [--entries 2000000] [--claim N]
                                              [--path /tmp/FILE.zip] [--compare]

Writes (once; kept for later runs) a zip of ``--entries`` folder entries — a local header and a
central directory entry each, names of 8 bytes, zip64 end records: ~184 MB for 2,000,000, the
shape of the hostile pass's 174 MB zip — then, in a fresh Python process each, refuses it
with :func:`mocapqa.jobs.archive.unpack` at the default ``archive_max_members`` and prints
the seconds taken and the memory the process grew by (its peak resident size, ``VmHWM``, less
its resident size before the call). ``--compare`` also measures ``zipfile.ZipFile`` opening
it, which is what the check used to wait for (Linux only: ``/proc/self/status``).
``--claim N`` makes the end records say ``N`` entries (a lie ``zipfile`` ignores: it reads
entries until the directory's size is used up), so the refusal comes from walking the
directory's entries up to the limit instead of from the count.
"""

from __future__ import annotations

import argparse
import json
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LOCAL = struct.Struct("<4s5H3L2H")
CENTRAL = struct.Struct("<4s6H3L5H2L")
END64 = struct.Struct("<4sQ2H2L4Q")
LOCATOR = struct.Struct("<4sLQL")
END = struct.Struct("<4s4H2LH")


def write_zip(path: Path, entries: int, claim: int | None = None) -> None:
    """A zip of ``entries`` empty folder entries, written by hand (zipfile would hold a
    ZipInfo per entry while writing); its end records say ``claim`` entries when given."""
    offsets = []
    with path.open("wb") as out:
        for i in range(entries):
            name = f"{i:07d}/".encode()
            offsets.append(out.tell())
            out.write(LOCAL.pack(b"PK\x03\x04", 20, 0, 0, 0, 0, 0, 0, 0, len(name), 0) + name)
        start = out.tell()
        for i, offset in enumerate(offsets):
            name = f"{i:07d}/".encode()
            fixed = (b"PK\x01\x02", 20, 20, 0, 0, 0, 0, 0, 0, 0, len(name), 0, 0, 0, 0)
            out.write(CENTRAL.pack(*fixed, 0o40755 << 16 | 0x10, offset) + name)
        size = out.tell() - start
        record = out.tell()
        said = entries if claim is None else claim
        out.write(END64.pack(b"PK\x06\x06", 44, 45, 45, 0, 0, said, said, size, start))
        out.write(LOCATOR.pack(b"PK\x06\x07", 0, record, 1))
        out.write(END.pack(b"PK\x05\x06", 0, 0, 0xFFFF, 0xFFFF, 0xFFFFFFFF, 0xFFFFFFFF, 0))


def status_kb(field: str) -> int:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(f"{field}:"):
            return int(line.split()[1])
    raise RuntimeError(f"no {field} in /proc/self/status")


def measure(path: Path, how: str) -> dict[str, object]:
    """Refuse (or, ``zipfile``, open) the archive in this process; the figures."""
    import zipfile

    from mocapqa.config import Settings
    from mocapqa.errors import TooLargeError
    from mocapqa.jobs.archive import unpack

    settings = Settings()
    max_bytes = int(settings.archive_max_unpacked_mb * 1_000_000)
    with tempfile.TemporaryDirectory() as dest:
        before = status_kb("VmRSS")
        started = time.perf_counter()
        outcome = "accepted"
        try:
            if how == "zipfile":
                with zipfile.ZipFile(path) as archive:
                    outcome = f"opened: {len(archive.infolist())} entries"
            else:
                unpack(path, path.name, Path(dest), settings.archive_max_members, max_bytes)
        except TooLargeError as e:
            outcome = f"413 TooLargeError: {e}"
        seconds = time.perf_counter() - started
        grown = (status_kb("VmHWM") - before) / 1000
    return {"how": how, "seconds": round(seconds, 4), "memory_growth_mb": grown, "outcome": outcome}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--entries", type=int, default=2_000_000)
    parser.add_argument("--claim", type=int, default=None, help="entries the end records say")
    parser.add_argument("--path", type=Path, default=None)
    parser.add_argument("--compare", action="store_true", help="time zipfile.ZipFile too")
    parser.add_argument("--measure", choices=["unpack", "zipfile"], help=argparse.SUPPRESS)
    args = parser.parse_args()
    said = "" if args.claim is None else f"-said-{args.claim}"
    name = f"mocapqa-{args.entries}-folders{said}.zip"
    path = args.path or Path(tempfile.gettempdir()) / name
    if args.measure:
        print(json.dumps(measure(path, args.measure)))
        return
    if not path.exists():
        write_zip(path, args.entries, args.claim)
    claimed = "" if args.claim is None else f", end records saying {args.claim}"
    print(f"{path}: {path.stat().st_size / 1e6:.1f} MB, {args.entries} folder entries{claimed}")
    for how in ["unpack", *(["zipfile"] if args.compare else [])]:
        command = [sys.executable, __file__, "--path", str(path), "--measure", how]
        done = subprocess.run(command, capture_output=True, text=True, check=True, cwd=ROOT)
        print(done.stdout.strip())


if __name__ == "__main__":
    main()
