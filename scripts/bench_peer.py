#!/usr/bin/env python3
"""Peer benchmark: cube5's golden model against VTK's vtkFixedPointVolumeRayCastMapper.

Renders the same volume (the head phantom written once by `cube5 phantom`), the same transfer
function and the same parallel view with both renderers, for composite unshaded, composite
shaded and MIP at 256^2 and 512^2 pixels on 1 and 2 threads, and prints one markdown table:
both frame times and their ratio (VTK / cube5, above 1 = cube5 faster). Both images of every
case are written side by side (VTK left, cube5 right) as PNG into the output directory.

Run it through `make bench-peer`, which makes the virtual environment with the pinned VTK and
builds `cube5`; by hand: `.venv-peer/bin/python scripts/bench_peer.py --cube5 target/release/cube5`.

What is the same in both renderers and what is not: docs/measurements.md, section "Peer: VTK
fixed-point ray cast mapper".
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import re
import statistics
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

# The transfer function: cube5's `head` preset (TransferFunction::head_default, the default scene's),
# read from `cube5 transfer head` so that there is one copy. cube5's scene names the preset; VTK gets
# the same points as a vtkColorTransferFunction and a vtkPiecewiseFunction. Densities are normalized
# to the voxel range 0 ..= 2^bits - 1; alpha is the opacity of one voxel of path.
TF_PRESET = "head"

# Phong coefficients, the same numbers in the scene's `[shading]` and in vtkVolumeProperty.
AMBIENT, DIFFUSE, SPECULAR, SHININESS = 0.25, 0.65, 0.35, 24.0

# The view (degrees, cube5's convention: azimuth around z from +x, elevation above the xy plane).
AZIMUTH, ELEVATION = 30.0, 20.0

# The cases: name, cube5 `[render]` mode, shading.
CASES = [
    ("composite", "composite", False),
    ("composite shaded", "composite", True),
    ("mip", "mip", False),
]

# `cube5 render --repeat N` prints this line (after rendering N frames from one loaded volume).
REPEAT_RE = re.compile(
    r"time: frame ([0-9.]+) ms \(best of (\d+)\), ([0-9.]+) M samples/s, (\d+) threads?"
)
# Without --repeat (older cube5), one frame per process and this line; its time has 10 ms
# resolution (`{:.2} s`), so the script runs the process several times and keeps the best.
RENDERED_RE = re.compile(r"rendered .* pixels in ([0-9.]+) s \((.*)\)")
SAMPLES_RE = re.compile(r"(\d+) samples")


class BenchError(Exception):
    """One line for the user, then a non-zero exit."""


def say(msg: str) -> None:
    print(msg, flush=True)


# =================================================================================================
# Machine and view
# =================================================================================================


def cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def load_average() -> str:
    """The 1-minute load average (other jobs on the machine slow both renderers alike)."""
    try:
        return Path("/proc/loadavg").read_text().split()[0]
    except OSError:
        return "n/a"


def view_direction(azimuth: float, elevation: float) -> tuple[float, float, float]:
    """cube5's View::direction (model/src/render.rs): unit vector from the eye into the scene."""
    a, e = math.radians(azimuth), math.radians(elevation)
    return (-math.cos(e) * math.cos(a), -math.cos(e) * math.sin(a), -math.sin(e))


def slice_step(direction: tuple[float, float, float]) -> float:
    """Distance along a ray between two slices of cube5's major axis (unit spacing): the pipeline's
    sample spacing at one sample per slice (SliceSetup::ratio in model/src/render.rs)."""
    return 1.0 / max(abs(c) for c in direction)


# =================================================================================================
# cube5
# =================================================================================================


def transfer_points(cube5: Path) -> list[tuple[float, tuple[float, float, float, float]]]:
    """The points of cube5's transfer function preset TF_PRESET (`cube5 transfer NAME`)."""
    out = subprocess.run([cube5, "transfer", TF_PRESET], capture_output=True, text=True)
    if out.returncode != 0:
        raise BenchError(f"cube5 transfer {TF_PRESET} failed: {out.stderr.strip()}")
    points = []
    for line in out.stdout.splitlines():
        d, r, g, b, a = (float(x) for x in line.split())
        points.append((d, (r, g, b, a)))
    if len(points) < 2:
        raise BenchError(f"cube5 transfer {TF_PRESET} printed {len(points)} points")
    return points


def scene_toml(
    volume: Path, size: int, bits: int, mode: str, shading: bool, pixels: int
) -> str:
    return f"""# Written by scripts/bench_peer.py.
[volume]
file = "{volume}"
format = "raw"
dims = [{size}, {size}, {size}]
type = "u16"
bits = {bits}

[view]
azimuth = {AZIMUTH}
elevation = {ELEVATION}
projection = "parallel"

[image]
width = {pixels}
height = {pixels}

[render]
mode = "{mode}"
shading = {"true" if shading else "false"}

[transfer]
preset = "{TF_PRESET}"

[shading]
ambient = {AMBIENT}
diffuse = {DIFFUSE}
specular = {SPECULAR}
shininess = {SHININESS}

[run]
target = "model"
renderer = "pipeline"
"""


def cube5_has_repeat(cube5: Path) -> bool:
    out = subprocess.run([cube5, "render", "--help"], capture_output=True, text=True)
    return "--repeat" in out.stdout


@dataclass
class Cube5Time:
    ms: float
    msamples: float | None
    frames: int


def run_cube5(
    cube5: Path, scene: Path, png: Path, threads: int, frames: int, repeat: bool
) -> Cube5Time:
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    cmd = [str(cube5), "render", str(scene), "-o", str(png)]
    if repeat:
        out = subprocess.run(cmd + ["--repeat", str(frames)], capture_output=True, text=True, env=env)
        if out.returncode != 0:
            raise BenchError(f"cube5 render failed: {out.stderr.strip() or out.stdout.strip()}")
        m = REPEAT_RE.search(out.stdout + out.stderr)
        if not m:
            raise BenchError(f"cube5 render --repeat printed no `time: frame ...` line:\n{out.stdout}")
        return Cube5Time(float(m.group(1)), float(m.group(3)), int(m.group(2)))
    best: Cube5Time | None = None
    for _ in range(frames):
        out = subprocess.run(cmd, capture_output=True, text=True, env=env)
        if out.returncode != 0:
            raise BenchError(f"cube5 render failed: {out.stderr.strip() or out.stdout.strip()}")
        m = RENDERED_RE.search(out.stdout + out.stderr)
        if not m:
            raise BenchError(f"cube5 render printed no `rendered ... in X s` line:\n{out.stdout}")
        secs = float(m.group(1))
        s = SAMPLES_RE.search(m.group(2))
        msamples = int(s.group(1)) / secs / 1e6 if s and secs > 0 else None
        if best is None or secs * 1e3 < best.ms:
            best = Cube5Time(secs * 1e3, msamples, frames)
    assert best is not None
    return best


# =================================================================================================
# VTK
# =================================================================================================


def import_vtk():
    """VTK's modules, or a BenchError naming what is missing."""
    # Without an X display, ask the wheel for its EGL window (Mesa's llvmpipe or a GPU) at once
    # instead of letting it try X first and print a warning; OSMesa remains its own fallback.
    if not os.environ.get("DISPLAY"):
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    try:
        import numpy as np
        import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (registers the OpenGL factories)
        import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401
        from vtkmodules import vtkCommonCore, vtkCommonDataModel, vtkIOImage, vtkRenderingCore
        from vtkmodules import vtkRenderingVolume
        from vtkmodules.util import numpy_support
        from vtkmodules.vtkCommonCore import vtkVersion
    except ImportError as e:
        raise BenchError(
            f"VTK is not installed in this Python ({sys.executable}): {e}; run `make bench-peer`"
        ) from e
    return {
        "np": np,
        "core": vtkCommonCore,
        "data": vtkCommonDataModel,
        "io": vtkIOImage,
        "render": vtkRenderingCore,
        "volume": vtkRenderingVolume,
        "numpy_support": numpy_support,
        "version": vtkVersion.GetVTKVersion(),
    }


def vtk_smoke_test(v) -> str:
    """Renders one small offscreen frame; returns the render window's class or raises BenchError."""
    win = v["render"].vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(16, 16)
    ren = v["render"].vtkRenderer()
    ren.SetBackground(1.0, 0.0, 0.0)
    win.AddRenderer(ren)
    try:
        win.Render()
    except Exception as e:  # VTK reports most failures on stderr, some as exceptions
        raise BenchError(f"VTK cannot render offscreen: {e}") from e
    grab = v["render"].vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.ReadFrontBufferOff()
    grab.Update()
    pixels = v["numpy_support"].vtk_to_numpy(grab.GetOutput().GetPointData().GetScalars())
    if pixels.size == 0 or int(pixels[0][0]) != 255:
        raise BenchError(
            "VTK cannot render offscreen: a test frame came back empty (no EGL/OSMesa/X; on "
            "Debian: apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri)"
        )
    name = win.GetClassName()
    win.Finalize()
    return name


def vtk_volume(v, raw: Path, size: int, bits: int):
    np = v["np"]
    voxels = np.fromfile(raw, dtype="<u2")
    if voxels.size != size**3:
        raise BenchError(f"{raw}: {voxels.size} voxels, expected {size}^3")
    img = v["data"].vtkImageData()
    img.SetDimensions(size, size, size)  # x fastest, as cube5's raw files
    img.SetSpacing(1.0, 1.0, 1.0)
    img.SetOrigin(0.0, 0.0, 0.0)  # voxel centres at integer positions, as cube5's
    arr = v["numpy_support"].numpy_to_vtk(voxels, deep=True, array_type=v["core"].VTK_UNSIGNED_SHORT)
    arr.SetName("density")
    img.GetPointData().SetScalars(arr)
    return img, (1 << bits) - 1


@dataclass
class VtkTime:
    best_ms: float
    median_ms: float
    mapper_ms: float  # the mapper's own time of its best frame (GetTimeToDraw)


def render_vtk(
    v, img, max_value: int, mode: str, shading: bool, pixels: int, threads: int,
    warmup: int, frames: int, png: Path, tf_points,
) -> VtkTime:
    R = v["render"]
    v["core"].vtkMultiThreader.SetGlobalMaximumNumberOfThreads(threads)
    try:
        v["core"].vtkSMPTools.Initialize(threads)
    except AttributeError:
        pass

    mapper = v["volume"].vtkFixedPointVolumeRayCastMapper()
    mapper.SetInputData(img)
    mapper.SetNumberOfThreads(threads)
    # One ray per pixel and cube5's sample spacing, never adapted to a frame rate.
    mapper.AutoAdjustSampleDistancesOff()
    mapper.LockSampleDistanceToInputSpacingOff()
    mapper.SetImageSampleDistance(1.0)
    direction = view_direction(AZIMUTH, ELEVATION)
    mapper.SetSampleDistance(slice_step(direction))
    mapper.SetInteractiveSampleDistance(slice_step(direction))

    prop = R.vtkVolumeProperty()
    prop.SetInterpolationTypeToLinear()
    colour = R.vtkColorTransferFunction()
    opacity = v["data"].vtkPiecewiseFunction()
    if mode == "mip":
        # cube5's MIP is the grey of the largest density (0 ..= max value -> black ..= white).
        mapper.SetBlendModeToMaximumIntensity()
        colour.AddRGBPoint(0.0, 0.0, 0.0, 0.0)
        colour.AddRGBPoint(float(max_value), 1.0, 1.0, 1.0)
        opacity.AddPoint(0.0, 1.0)
        opacity.AddPoint(float(max_value), 1.0)
        prop.ShadeOff()
    else:
        mapper.SetBlendModeToComposite()
        for d, (r, g, b, a) in tf_points:
            colour.AddRGBPoint(d * max_value, r, g, b)
            opacity.AddPoint(d * max_value, a)
        # Alpha is the opacity of one voxel of path in both (cube5 corrects it to its step).
        prop.SetScalarOpacityUnitDistance(1.0)
        prop.SetShade(1 if shading else 0)
        prop.SetAmbient(AMBIENT)
        prop.SetDiffuse(DIFFUSE)
        prop.SetSpecular(SPECULAR)
        prop.SetSpecularPower(SHININESS)
    colour.ClampingOn()
    opacity.ClampingOn()
    prop.SetColor(colour)
    prop.SetScalarOpacity(opacity)

    volume = R.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)

    ren = R.vtkRenderer()
    ren.SetBackground(0.0, 0.0, 0.0)
    ren.AddVolume(volume)
    ren.SetTwoSidedLighting(1)  # cube5 shades two-sided (|n.l|)
    # cube5's light: one white headlight along the view. VTK's default light has a black ambient
    # colour, and its volume shading scales the ambient term by it, so say white.
    light = R.vtkLight()
    light.SetLightTypeToHeadlight()
    light.SetAmbientColor(1.0, 1.0, 1.0)
    light.SetDiffuseColor(1.0, 1.0, 1.0)
    light.SetSpecularColor(1.0, 1.0, 1.0)
    light.SetIntensity(1.0)
    ren.AutomaticLightCreationOff()
    ren.AddLight(light)
    win = R.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetMultiSamples(0)
    win.SetSize(pixels, pixels)
    win.AddRenderer(ren)

    # cube5's camera (model/src/camera.rs): looks along `direction` at the volume centre, up from
    # world z (y when looking along z), half the shorter image side = 1.02 x the bounding radius.
    n = img.GetDimensions()
    centre = [(n[a] - 1) * 0.5 for a in range(3)]
    radius = 0.5 * math.sqrt(sum(float(n[a]) ** 2 for a in range(3)))
    cam = ren.GetActiveCamera()
    cam.ParallelProjectionOn()
    cam.SetFocalPoint(*centre)
    cam.SetPosition(*[centre[a] - direction[a] * 4.0 * radius for a in range(3)])
    cam.SetViewUp(*((0.0, 1.0, 0.0) if abs(direction[2]) > 0.999 else (0.0, 0.0, 1.0)))
    cam.SetParallelScale(radius * 1.02)
    ren.ResetCameraClippingRange()

    for _ in range(warmup):
        win.Render()
    times, mapper_times = [], []
    for _ in range(frames):
        t0 = time.perf_counter()
        win.Render()
        times.append((time.perf_counter() - t0) * 1e3)
        mapper_times.append(mapper.GetTimeToDraw() * 1e3)

    grab = R.vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.ReadFrontBufferOff()
    grab.SetInputBufferTypeToRGB()
    grab.Update()
    writer = v["io"].vtkPNGWriter()
    writer.SetFileName(str(png))
    writer.SetInputData(grab.GetOutput())
    writer.Write()
    win.Finalize()
    best = min(range(frames), key=lambda i: times[i])
    return VtkTime(times[best], statistics.median(times), mapper_times[best])


def side_by_side(v, left: Path, right: Path, out: Path) -> float:
    """VTK's image | 8 grey pixels | cube5's image, as one PNG (both read back through VTK).
    Returns the mean absolute difference of the two images in 8-bit codes (a check that both
    render the same scene, not a measure of either's accuracy)."""
    np, ns = v["np"], v["numpy_support"]
    imgs = []
    for p in (left, right):
        r = v["io"].vtkPNGReader()
        r.SetFileName(str(p))
        r.Update()
        o = r.GetOutput()
        w, h, _ = o.GetDimensions()
        a = ns.vtk_to_numpy(o.GetPointData().GetScalars()).reshape(h, w, -1)[:, :, :3]
        imgs.append(a)
    h = max(a.shape[0] for a in imgs)
    pad = lambda a: np.pad(a, ((0, h - a.shape[0]), (0, 0), (0, 0)))  # noqa: E731
    gap = np.full((h, 8, 3), 96, dtype=np.uint8)
    both = np.ascontiguousarray(np.concatenate([pad(imgs[0]), gap, pad(imgs[1])], axis=1))
    img = v["data"].vtkImageData()
    img.SetDimensions(both.shape[1], both.shape[0], 1)
    img.GetPointData().SetScalars(ns.numpy_to_vtk(both.reshape(-1, 3), deep=True))
    w = v["io"].vtkPNGWriter()
    w.SetFileName(str(out))
    w.SetInputData(img)
    w.Write()
    if imgs[0].shape != imgs[1].shape:
        return float("nan")
    return float(np.abs(imgs[0].astype(np.int32) - imgs[1].astype(np.int32)).mean())


# =================================================================================================
# Main
# =================================================================================================


def ratio(vtk_ms: float, cube5_ms: float) -> str:
    """VTK's frame time over cube5's (above 1: cube5 faster)."""
    return f"{vtk_ms / cube5_ms:.3f}" if cube5_ms > 0 else "n/a (cube5 below the timer's resolution)"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cube5", type=Path, default=Path("target/release/cube5"))
    ap.add_argument("--out", type=Path, default=Path("target/bench-peer"))
    ap.add_argument("--size", type=int, default=256, help="phantom edge in voxels (>= 192)")
    ap.add_argument("--bits", type=int, default=12)
    ap.add_argument("--pixels", default="256,512", help="image edges, comma-separated")
    ap.add_argument("--threads", default="1,2", help="thread counts, comma-separated")
    ap.add_argument("--cases", default=",".join(c[0] for c in CASES))
    ap.add_argument("--warmup", type=int, default=2, help="VTK frames before timing")
    ap.add_argument("--frames", type=int, default=5, help="timed frames per case (best is kept)")
    ap.add_argument("--cube5-frames", type=int, default=3,
                    help="cube5 frames per case (--repeat N, or N processes without it)")
    ap.add_argument("--smoke-test", action="store_true",
                    help="only check that VTK renders offscreen, then exit")
    args = ap.parse_args()

    v = import_vtk()
    window = vtk_smoke_test(v)
    if args.smoke_test:
        say(f"VTK {v['version']} renders offscreen ({window})")
        return 0

    cube5 = args.cube5.resolve()
    if not cube5.is_file():
        raise BenchError(f"{cube5}: no cube5 binary (cargo build --release -p cube5-cli)")
    pixels = [int(p) for p in args.pixels.split(",")]
    threads = [int(t) for t in args.threads.split(",")]
    known = {c[0]: c for c in CASES}
    cases = []
    for name in args.cases.split(","):
        if name not in known:
            raise BenchError(f"--cases: unknown case `{name}` (known: {', '.join(known)})")
        cases.append(known[name])
    args.out.mkdir(parents=True, exist_ok=True)
    out = args.out.resolve()

    raw = out / f"head{args.size}-{args.bits}bit.raw"
    if not raw.exists():
        r = subprocess.run(
            [cube5, "phantom", "head", "--size", str(args.size), "--bits", str(args.bits), "-o", raw],
            capture_output=True, text=True,
        )
        if r.returncode != 0:
            raise BenchError(f"cube5 phantom failed: {r.stderr.strip()}")
    img, max_value = vtk_volume(v, raw, args.size, args.bits)
    tf_points = transfer_points(cube5)
    repeat = cube5_has_repeat(cube5)
    machine = f"{cpu_model()}, {os.cpu_count()} cores"
    load_start = load_average()
    say(f"machine: {machine}; VTK {v['version']} ({window}); volume {raw.name} "
        f"({args.size}^3, {args.bits}-bit); transfer function `{TF_PRESET}` ({len(tf_points)} points); view azimuth {AZIMUTH} elevation {ELEVATION}, parallel")
    say(f"cube5: {cube5} ({'--repeat' if repeat else 'no --repeat: one frame per process, best of'} "
        f"{args.cube5_frames}); VTK: best of {args.frames} frames after {args.warmup} warm-up")

    rows = []
    for name, mode, shading in cases:
        for px in pixels:
            # Kept beside the images, so that `cube5 render SCENE --repeat N` can time a case
            # alone: OUT/composite-0-256.toml (mode, shading 0/1, pixels).
            scene = out / f"{mode}-{int(shading)}-{px}.toml"
            scene.write_text(scene_toml(raw, args.size, args.bits, mode, shading, px))
            for t in threads:
                stem = f"{name.replace(' ', '-')}-{px}-t{t}"
                vtk_png, c5_png = out / f"{stem}-vtk.png", out / f"{stem}-cube5.png"
                vt = render_vtk(v, img, max_value, mode, shading, px, t,
                                args.warmup, args.frames, vtk_png, tf_points)
                ct = run_cube5(cube5, scene, c5_png, t, args.cube5_frames, repeat)
                diff = side_by_side(v, vtk_png, c5_png, out / f"{stem}.png")
                row = (name, f"{px}x{px}", t, vt, ct)
                rows.append(row)
                say(f"{name}, {px}^2, {t} thread(s): VTK {vt.best_ms:.1f} ms "
                    f"(median {vt.median_ms:.1f}, mapper {vt.mapper_ms:.1f}), "
                    f"cube5 {ct.ms:.1f} ms, ratio {ratio(vt.best_ms, ct.ms)}; images differ by "
                    f"{diff:.1f}/255 on average")

    say("")
    say(f"load average (1 min) at the start {load_start}, at the end {load_average()}")
    say(f"Machine: {machine}. VTK {v['version']} `vtkFixedPointVolumeRayCastMapper`, "
        f"head phantom {args.size}^3 ({args.bits}-bit), transfer function `{TF_PRESET}`, view azimuth {AZIMUTH:g} elevation "
        f"{ELEVATION:g}, parallel. Ratio = VTK ms / cube5 ms (> 1: cube5 faster).")
    say("")
    say("| case | size | threads | VTK ms | VTK mapper ms | cube5 ms | cube5 M samples/s | ratio |")
    say("|------|------|--------:|-------:|--------------:|---------:|------------------:|------:|")
    for name, size, t, vt, ct in rows:
        ms = f"{ct.msamples:.1f}" if ct.msamples is not None else "n/a"
        say(f"| {name} | {size} | {t} | {vt.best_ms:.1f} | {vt.mapper_ms:.1f} | {ct.ms:.1f} | "
            f"{ms} | {ratio(vt.best_ms, ct.ms)} |")
    say("")
    say(f"images (VTK left, cube5 right): {out}/*-t*.png")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except BenchError as e:
        print(f"bench-peer: {e}", file=sys.stderr)
        sys.exit(2)
