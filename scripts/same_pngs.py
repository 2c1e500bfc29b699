#!/usr/bin/env python3
"""Render every example scene (scenes/*.toml), the default scene, and any extra scenes with two
`cube5` binaries and check that the PNG files are byte for byte the same: the evidence a speed-up
of the golden model keeps every output bit.

    scripts/same_pngs.py BEFORE_CUBE5 AFTER_CUBE5 [EXTRA.toml ...] [--views N] [--out DIR]

Each scene renders with `--target model` (no RTL), at its own view and, with `--views N`, at N more
views (azimuth and elevation overrides spread over the sphere: other slice axes and sweep
directions). Exit status 0 when every pair is identical, 1 when any differs, 2 when a render fails
in one binary but not the other (a scene both refuse alike counts as the same).
"""

from __future__ import annotations

import argparse
import filecmp
import subprocess
import sys
import tempfile
from pathlib import Path


def render(cube5: Path, scene: str | None, out: Path, extra: list[str]) -> tuple[int, str]:
    cmd = [str(cube5), "render"] + ([scene] if scene else []) + ["-o", str(out), "--target", "model"]
    r = subprocess.run(cmd + extra, capture_output=True, text=True)
    return r.returncode, (r.stderr.strip().splitlines() or [""])[-1]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("before", type=Path)
    ap.add_argument("after", type=Path)
    ap.add_argument("extra", nargs="*", help="more scene files")
    ap.add_argument("--views", type=int, default=0, help="more views per scene (overrides)")
    ap.add_argument("--out", type=Path, help="keep the images here (default: a temporary dir)")
    args = ap.parse_args()

    root = Path(__file__).resolve().parent.parent
    scenes: list[str | None] = [None] + [str(p) for p in sorted((root / "scenes").glob("*.toml"))]
    scenes += args.extra
    views: list[list[str]] = [[]]
    for n in range(args.views):
        az, el = (n * 137.5 + 11.0) % 360.0, -80.0 + (n * 57.0) % 160.0
        views.append(["--azimuth", f"{az:.1f}", "--elevation", f"{el:.1f}"])

    differ = failed = same = 0
    with tempfile.TemporaryDirectory(prefix="same-pngs-") as tmp:
        out = args.out or Path(tmp)
        out.mkdir(parents=True, exist_ok=True)
        for scene in scenes:
            name = Path(scene).stem if scene else "default"
            for v, extra in enumerate(views):
                a, b = out / f"{name}-v{v}-before.png", out / f"{name}-v{v}-after.png"
                ra, ea = render(args.before, scene, a, extra)
                rb, eb = render(args.after, scene, b, extra)
                what = f"{name} {' '.join(extra) or '(scene view)'}"
                if ra != 0 or rb != 0:
                    if ra != 0 and rb != 0 and ea == eb:
                        print(f"same (refused by both): {what}: {ea}")
                        same += 1
                    else:
                        print(f"FAILED in one: {what}: before {ra} {ea!r}, after {rb} {eb!r}")
                        failed += 1
                elif filecmp.cmp(a, b, shallow=False):
                    print(f"same: {what}")
                    same += 1
                else:
                    print(f"DIFFER: {what} ({a}, {b})")
                    differ += 1
    print(f"{same} same, {differ} differ, {failed} failed in one binary")
    return 2 if failed else (1 if differ else 0)


if __name__ == "__main__":
    sys.exit(main())
