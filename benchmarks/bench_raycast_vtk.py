"""vrlib's ray caster beside VTK's CPU ray caster, in one process (``make bench``).

Both render the same 256^3 volume into a 512^2 image with a parallel projection, the same
sample distance and the same transfer function; VTK's automatic sample-distance adjustment is
off. VTK's fixed-point caster (``vtkFixedPointVolumeRayCastMapper`` through pyvista, offscreen
via EGL) has only trilinear sampling and 8-bit output. Its opacity table is the glow model in
VTK's units: ``a_unit(v) = 1 - exp(-density(v) * unit_distance)``, white colour, so its grey
image is the glow alpha. Each image's error is measured against ``render_reference`` of the
analytic field. Scenes: a dense one (Marschner-Lobb under Glow: nothing can be skipped), a
sparse one (a few blobs under a thresholded ramp: under 10% of the volume visible) and a
smooth blob with long low tails (everything faintly visible, little to skip).

VTK's GPU ray caster, what pyvista's ``add_volume`` uses, renders each scene too, at its
default half-voxel sample distance, beside vrlib at the same step: on a machine without a
GPU it runs on Mesa's llvmpipe (the OpenGL renderer is printed).

Prints a table (times are the best of three; ratios are ours / VTK's), the GPU mapper's
table and the dense scene's times at 512^3, and writes
``build/results/benchmarks/raycast_vtk.json``.
"""

from __future__ import annotations

import os
import platform
import subprocess
import sys
import time
import tracemalloc
from functools import partial

os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")

import numpy as np  # noqa: E402
from _report import best_of, best_of_each, markdown, write_record  # noqa: E402

import data_gen  # noqa: E402
import vrlib  # noqa: E402

N, SIZE, STEP = 256, 512, 1.0
LARGE_N = 512
VIEW = {"azimuth": 30.0, "elevation": 20.0}


def scenes():
    ramp = np.linspace(0.0, 1.0, 11)
    sparse_tf = vrlib.LookupTransfer(6.0 * np.clip((ramp - 0.1) / 0.9, 0.0, None),
                                     value_range=(0.0, 1.0))
    blobs = data_gen.make_field("random-blobs", count=6, seed=4, sigma=(0.06, 0.1))
    return {
        "dense (Marschner-Lobb, Glow)": (data_gen.make_field("marschner-lobb"), vrlib.Glow(1.0)),
        "sparse (6 blobs, ramp from 0.1)": (blobs, sparse_tf),
        "long tails (blob sigma 0.35, Glow 2)": (data_gen.make_field("gaussian-blob", sigma=0.35),
                                                 vrlib.Glow(2.0)),
    }




class VTKCaster:
    """VTK's fixed-point CPU ray caster (or, with ``mapper="gpu"``, its GPU ray caster on
    whatever OpenGL the machine has: Mesa's llvmpipe without a GPU) set up to render exactly
    the emission-absorption model of ``transfer``: segment opacity from the density at the
    sample distance, colour from the emission (premultiplied over black)."""

    def __init__(self, volume, view, transfer, sample_distance, mapper="fixed_point"):
        import pyvista as pv
        import vtk

        self.vtk = vtk
        nz, ny, nx = volume.shape
        grid = pv.ImageData(dimensions=(nx, ny, nz), spacing=tuple(volume.spacing),
                            origin=tuple(volume.origin))
        grid.point_data["v"] = np.ascontiguousarray(volume.data, dtype=np.float32).ravel()
        self.plotter = pv.Plotter(off_screen=True, window_size=(view.width, view.height))
        self.plotter.set_background("black")
        actor = self.plotter.add_volume(grid, scalars="v", mapper=mapper,
                                        show_scalar_bar=False)
        self.mapper = actor.GetMapper()
        self.mapper.SetAutoAdjustSampleDistances(0)
        self.mapper.SetLockSampleDistanceToInputSpacing(0)
        self.mapper.SetSampleDistance(sample_distance)
        self.mapper.SetImageSampleDistance(1.0)
        prop = actor.GetProperty()
        unit = sample_distance
        opacity = vtk.vtkPiecewiseFunction()
        colour = vtk.vtkColorTransferFunction()
        lo, hi = volume.value_range
        values = np.linspace(lo, hi, 1025)
        densities = np.asarray(transfer.opacity_density(values), dtype=float)
        emission = np.asarray(transfer.emission(values), dtype=float)
        for v, density, rgb in zip(values, densities, emission, strict=True):
            opacity.AddPoint(float(v), float(-np.expm1(-density * unit)))
            colour.AddRGBPoint(float(v), *(float(c) for c in rgb))
        prop.SetScalarOpacity(opacity)
        prop.SetScalarOpacityUnitDistance(unit)
        prop.SetColor(colour)
        prop.ShadeOff()
        prop.SetInterpolationTypeToLinear()
        camera = self.plotter.renderer.GetActiveCamera()
        camera.ParallelProjectionOn()
        camera.SetFocalPoint(*view.center)
        camera.SetPosition(*(view.center - 10.0 * view.radius * view.forward))
        camera.SetViewUp(*view.up)
        camera.SetParallelScale(0.5 * view.height * view.pixel_size)
        self.plotter.renderer.ResetCameraClippingRange()
        self.plotter.camera_set = True  # keep pyvista from resetting the camera on render
        self.window = self.plotter.ren_win

    def renderer(self):
        """The OpenGL renderer's name (``llvmpipe ...`` on Mesa without a GPU)."""
        info = self.window.ReportCapabilities()
        found = [line.split(":", 1)[1].strip() for line in info.splitlines()
                 if line.lower().startswith("opengl renderer")]
        return found[0] if found else "unknown"

    def render(self, threads):
        if hasattr(self.mapper, "SetNumberOfThreads"):  # the GPU mapper has none
            self.mapper.SetNumberOfThreads(threads)
        self.window.Render()
        self.window.WaitForCompletion()

    def image(self):
        """The red channel: the glow model's alpha when the emission is white."""
        return self.colour()[..., 0]

    def colour(self):
        """Premultiplied RGB (the volume composited over black), 8 bits per channel."""
        return self.plotter.screenshot(return_img=True)[..., :3] / 255.0

    def close(self):
        self.plotter.close()


def large_volume(view):
    """The dense scene at ``LARGE_N``^3 (512 MiB as float32), beside VTK's fixed-point caster
    on 2 threads, times only (the issue's targets hold "also at 512^3"; a reference image at
    that size would take far longer than the renders)."""
    field, transfer = scenes()["dense (Marschner-Lobb, Glow)"]
    volume = field.sample(LARGE_N, dtype=np.float32)

    def ours():
        return vrlib.render(volume, view, filter="trilinear", transfer=transfer, step=STEP,
                            threads=2, early_termination=0.999)

    ours()
    out = {"ours_2t_s": best_of(ours)[0]}
    caster = VTKCaster(volume, view, transfer, STEP * float(volume.spacing.min()))
    caster.render(2)
    out["vtk_2t_s"] = best_of(lambda: caster.render(2))[0]
    caster.close()
    return out


def jit_times():
    """First render in a fresh process with an empty cache (compile) and with a warm cache.

    The cache is shared by the filters: the kernel is compiled once for all of them."""
    code = ("import time; t = time.perf_counter(); import data_gen, vrlib; "
            "v = data_gen.make_field('gaussian-blob').sample(16); "
            "vrlib.render(v, vrlib.View.orbit(size=8), filter='{f}'); "
            "print(time.perf_counter() - t)")
    import tempfile

    out = {}
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        for f in ("trilinear", "catmull-rom"):
            runs = [float(subprocess.run([sys.executable, "-c", code.format(f=f)], env=env,
                                         capture_output=True, text=True, check=True).stdout)
                    for _ in range(2)]
            out[f] = {"cold_s": runs[0], "cached_s": runs[1]}
    return out


def main():
    rows, gpu_rows = [], []
    record = {"machine": {"cpu": platform.processor() or platform.machine(),
                          "cores": os.cpu_count(), "python": platform.python_version(),
                          "vtk": None}, "scenes": {}}
    view = vrlib.View.orbit(size=SIZE, **VIEW)
    for label, (field, transfer) in scenes().items():
        volume = field.sample(N, dtype=np.float32)
        ds = STEP * float(volume.spacing.min())
        visible = float(np.mean(np.asarray(transfer.opacity_density(volume.data)) > 0))
        print(f"[{label}] reference image...", flush=True)
        ref = vrlib.render_reference(field, view, transfer=transfer, tol=1e-5).alpha
        scene = {"visible_fraction": visible}

        def ours(threads, filt="trilinear", skip=True, early=0.999, volume=volume,
                 transfer=transfer, step=STEP):
            return vrlib.render(volume, view, filter=filt, transfer=transfer, step=step,
                                threads=threads, empty_space_skipping=skip,
                                early_termination=early)

        start = time.perf_counter()
        ours(2)  # compile (cached after the first run) and build the skipping pyramid
        scene["first_render_s"] = time.perf_counter() - start
        timed = best_of_each({threads: partial(ours, threads) for threads in (1, 2)})
        for threads, (t, img) in timed.items():
            scene[f"ours_{threads}t_s"] = t
            scene["ours_samples"] = img.stats.samples
            scene["ours_rmse"] = vrlib.metrics.rmse(img.alpha, ref)
        tracemalloc.start()
        ours(2)
        scene["ours_peak_bytes"] = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        scene["volume_bytes"] = int(volume.data.nbytes)
        scene["no_skip_2t_s"], _ = best_of(lambda: ours(2, skip=False, early=1.0))
        t, img = best_of(lambda: ours(2, step=2 * STEP))
        scene["step2_2t_s"], scene["step2_rmse"] = t, vrlib.metrics.rmse(img.alpha, ref)
        t, img = best_of(lambda: ours(2, filt="catmull-rom"))
        scene["catmull_rom_2t_s"], scene["catmull_rom_rmse"] = t, vrlib.metrics.rmse(img.alpha,
                                                                                      ref)
        caster = VTKCaster(volume, view, transfer, ds)
        import vtk

        record["machine"]["vtk"] = vtk.vtkVersion.GetVTKVersion()
        caster.render(2)
        timed = best_of_each({threads: partial(caster.render, threads) for threads in (1, 2)})
        for threads, (t, _) in timed.items():
            scene[f"vtk_{threads}t_s"] = t
        scene["vtk_rmse"] = vrlib.metrics.rmse(caster.image(), ref)
        caster.close()
        # pyvista's default: the GPU mapper at half a voxel, beside vrlib at the same step.
        gpu = VTKCaster(volume, view, transfer, 0.5 * ds, mapper="gpu")
        gpu.render(2)
        record["machine"]["opengl"] = gpu.renderer()
        scene["gpu_half_s"], _ = best_of(lambda gpu=gpu: gpu.render(2))
        scene["gpu_half_rmse"] = vrlib.metrics.rmse(gpu.image(), ref)
        gpu.close()
        t, img = best_of(lambda: ours(2, step=0.5 * STEP))
        scene["ours_half_2t_s"], scene["ours_half_rmse"] = t, vrlib.metrics.rmse(img.alpha, ref)
        gpu_rows.append([label, f"{t:.3f}", f"{scene['gpu_half_s']:.3f}",
                         f"{t / scene['gpu_half_s']:.2f}", f"{scene['ours_half_rmse']:.2e}",
                         f"{scene['gpu_half_rmse']:.2e}"])
        record["scenes"][label] = scene
        s = scene
        rows.append([
            label, f"{100 * visible:.1f}%",
            f"{s['ours_2t_s']:.3f}", f"{s['vtk_2t_s']:.3f}",
            f"{s['ours_2t_s'] / s['vtk_2t_s']:.2f}",
            f"{s['ours_rmse']:.2e}", f"{s['vtk_rmse']:.2e}",
            f"{s['ours_samples'] / s['ours_2t_s'] / 1e6:.0f}",
            f"{s['ours_1t_s'] / s['ours_2t_s']:.2f}", f"{s['vtk_1t_s'] / s['vtk_2t_s']:.2f}",
            f"{s['no_skip_2t_s'] / s['ours_2t_s']:.2f}",
            f"{s['step2_2t_s']:.3f} ({s['step2_rmse']:.1e})",
            f"{s['catmull_rom_2t_s']:.3f} ({s['catmull_rom_rmse']:.1e})",
            f"{s['ours_peak_bytes'] / 2**20:.1f} / {s['volume_bytes'] / 2**20:.0f}",
        ])
    record["large"] = large_volume(view)
    record["jit"] = jit_times()
    header = ["scene", "visible", "ours 2t (s)", "VTK 2t (s)", "ours/VTK", "ours rmse",
              "VTK rmse", "Msamples/s", "ours 1t/2t", "VTK 1t/2t", "skip speedup",
              "ours step 2 (s, rmse)", "Catmull-Rom (s, rmse)", "peak extra / volume (MiB)"]
    print(f"\n256^3 -> 512^2, parallel projection, step {STEP} voxel, trilinear unless named\n")
    print(markdown(header, rows))
    print(f"\nVTK's GPU mapper (pyvista's default; OpenGL renderer: "
          f"{record['machine'].get('opengl')}) at half a voxel, beside vrlib at step "
          f"{0.5 * STEP:g}, 2 threads\n")
    print(markdown(["scene", "ours (s)", "GPU mapper (s)", "ours/GPU", "ours rmse", "GPU rmse"],
                   gpu_rows))
    large = record["large"]
    print(f"\nThe dense scene at {LARGE_N}^3 -> {SIZE}^2 (float32, step {STEP}, times only): "
          f"ours {large['ours_2t_s']:.3f} s, VTK {large['vtk_2t_s']:.3f} s on 2 threads, "
          f"ours/VTK {large['ours_2t_s'] / large['vtk_2t_s']:.2f}\n")
    for f, t in record["jit"].items():
        print(f"JIT, first render in a new process, {f}: {t['cold_s']:.2f} s with an empty "
              f"cache, {t['cached_s']:.2f} s from the cache (one kernel serves every filter)")
    write_record("raycast_vtk", record)


if __name__ == "__main__":
    main()
