#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Renders the example maps and real normal maps at six footprints (0.5 to 64 texels) with the
reference P-NDF, the baked assets (uncompressed ndf-pyramid and tensor-ndf rank 16) and the smooth
BRDF, compares every render with the reference, compares NDF images of the assets with the
reference evaluator's over a range of footprints, and writes an HTML report.

    scripts/make-report.py [--bin build/bin] [--maps examples/out/maps] [--out out/report]
                           [--real-dir ../shared/data/normalmaps] [--no-real] [--only MAP ...]
                           [--image-size W,H] [--views V,...] [--ndf-sigmas S,...] [--show-sigmas S,...]

Procedural maps missing from --maps are generated with mapgen (the parameters of
examples/Makefile); their assets are taken from examples/out/{ndf,tensor} when the example build
made them (newer than the map), otherwise baked here. Real maps (REAL_MAPS, when --real-dir
exists) are cropped to 256 x 256 texels, so that every map has the same texel scale and bake cost.
Scenes: examples/scenes/plane_s{0.5,2,5,9.5,24,64}.json, 256 x 256 pixels: a plane tile of fixed
size seen from six distances, so the footprint grows from 0.5 to 64 texels while the tile covers
fewer pixels (the reference's cost per pixel grows with the footprint's area: this bounds it).
Every tool run is cached in OUT/work/cache.json, keyed by its arguments, the inputs' sizes and
modification times and the tool binary: a second run redoes only what changed.
The report is OUT/index.html; OUT/report.json holds the same figures for scripts."""

import argparse
import concurrent.futures
import hashlib
import html
import json
import math
import os
import struct
import subprocess
import sys
import threading
import time
import zlib

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
# Example maps and the mapgen arguments of examples/Makefile.
MAPS = {
    "scratches": ["scratches", "--size", "256", "--seed", "11"],
    "flakes": ["flakes", "--size", "256", "--seed", "12", "--cone", "12", "--cell", "8"],
    "brushed": ["brushed", "--size", "256", "--seed", "13"],
}
# Real maps of ../shared/data/normalmaps: one of each kind (Beckmann-like noise, sharp flakes,
# scratches, brushed), centre crops of CROP x CROP texels.
REAL_MAPS = {
    "real_isotropic": "isotropic_noise_256.png",
    "real_snail_flakes": "flakes_voronoi_sharp_snail_512.png",
    "real_curved_scratches": "scratches_curved_1024.png",
    "real_brushed": "brushed_blender_1024.png",
}
CROP = 256
# Views: (name, scene file); the footprint (mean over the plane) is in the scene's name.
VIEWS = ["s0.5", "s2", "s5", "s9.5", "s24", "s64"]
MODES = ["reference", "pyramid", "tensor16", "smooth"]
MODE_TITLES = {
    "reference": "reference P-NDF",
    "pyramid": "asset: ndf-pyramid",
    "tensor16": "asset: tensor-ndf rank 16",
    "smooth": "smooth GGX",
}
# NDF image comparison: footprints (texels) and the ones shown side by side.
# (The reference's NDF image costs in proportion to the footprint's area: 32 texels would take
# longer than all the others together.)
NDF_SIGMAS = [0.5, 1, 2, 4, 8, 11.3, 16]
SHOW_SIGMAS = [2, 8, 16]
# Runtime paths of an asset with flakes (ndfgen defaults): exact flakes up to max(4, sigma0) = 8
# texels, blended into the pyramid up to 8 * sqrt(2) = 11.3; the pyramid above.
FLAKES_UP_TO = 8.0
HANDOVER_UP_TO = 11.3
EXPOSURE = "0.5"
# Procedural glitter (Jakob et al. 2014): the example build's glitter asset (examples/Makefile),
# rendered at three distances (scenes glitter_{near,mid,far}.json: the same framing, the camera,
# plane and point light scaled by 0.1, 0.8 and 3.2) beside the smooth Beckmann BRDF of its
# roughness. At the scenes' 128 x 128 pixels the footprint grows from 0.25 to 8 texels of its
# 64 x 64 texel surface (49 facets per texel), that is from about 40 to 40,000 facets per pixel
# (over the Gaussian's effective area 4 pi sigma^2).
GLITTER_ARGS = ["--procedural", "glitter", "--glitter-asset", "--particles", "200000", "--alpha", "0.2",
                "--size", "64,64"]
GLITTER_VIEWS = ["near", "mid", "far"]
# Facets per texel of that surface, from its bake arguments.
GLITTER_FACETS_PER_TEXEL = (int(GLITTER_ARGS[GLITTER_ARGS.index("--particles") + 1]) /
                            math.prod(int(v) for v in GLITTER_ARGS[GLITTER_ARGS.index("--size") + 1].split(",")))
# Wang tiles (Cohen et al. 2003): the example build's tile set cut from the scratches map (16 tiles of
# 64 texels) on a plane far away, 32 x 32 tiles across (2048 texels), seen from straight above by a
# distant narrow camera under one directional light, so that the half vector hardly changes over the
# image and any repetition of the surface shows in the render (scenes wang_{tiled,repeated,
# reference}.json): the tile set, the scratches example simply repeated 8 x 8 times (its tensor
# asset) and the reference P-NDF of the materialised region (glintquery materialise).
WANG_BAKE = ["--tile-size", "64", "--ndf-res", "64"]
WANG_CELLS = "0,0,32,32"
WANG_REPEATS = 8  # example periods across the image: the repeated render's period is width / 8
# Tiny examples (Xing et al.): the example build's two tiny-example assets of a 32 x 32 crop of the
# brushed map (the arguments of examples/Makefile), on a plane seen from straight above under one
# directional light at two distances (scenes tiny_{near,far}.json, 128 x 128 pixels: 8 x 8 and
# 64 x 64 examples across, footprints of about 1 and 8 texels: the tiled asset's flakes path and its
# tile path), each beside the reference P-NDF of the same region of the asset's plane materialised
# as a normal map (glintquery materialise; scenes tiny_{near,far}_reference.json).
TINY_MAP = "brushed"
TINY_BAKE = {
    "tiled": ["--crop", "64,64,32", "--type", "tiled", "--rotate", "90"],
    "stochastic": ["--crop", "64,64,32", "--type", "stochastic", "--rotate-range", "0,360", "--scale-range",
                   "0.8,1.25", "--density", "0.3", "--seed", "5"],
}
TINY_VIEWS = {"near": 8, "far": 64}  # view: examples across the plane (the materialised cells per side)

_cache_lock = threading.Lock()


def fail(message):
    sys.stderr.write(f"make-report: error: {message}\n")
    sys.exit(1)


def fmt(x, digits=3):
    if x is None:
        return "-"
    if isinstance(x, float):
        if x != 0 and (abs(x) < 1e-3 or abs(x) >= 1e5):
            return f"{x:.{digits - 1}e}"
        return f"{x:.{digits}g}" if abs(x) < 1 else f"{x:.{digits}f}".rstrip("0").rstrip(".")
    return str(x)


def sigma_name(s):
    return f"{s:g}".replace(".", "p")


class Runner:
    """Runs tools, caching each run by its arguments, the inputs' sizes and times and the tool."""

    def __init__(self, bin_dir, work):
        self.bin = bin_dir
        self.path = os.path.join(work, "cache.json")
        try:
            with open(self.path) as f:
                self.cache = json.load(f)
        except (OSError, ValueError):
            self.cache = {}
        self.runs = 0
        self.cached = 0

    def tool(self, name):
        return os.path.join(self.bin, name)

    @staticmethod
    def stamp(path):
        st = os.stat(path)
        return f"{st.st_size}:{st.st_mtime_ns}"

    def run(self, args, inputs=(), outputs=(), capture_json=False):
        """Returns (parsed --json document or None, wall seconds of the run that made the outputs)."""
        args = [str(a) for a in args]
        exe = args[0]
        key_text = json.dumps([args, [self.stamp(p) for p in inputs],
                               self.stamp(exe) if os.path.exists(exe) else ""])
        key = hashlib.sha256(key_text.encode()).hexdigest()
        with _cache_lock:
            hit = self.cache.get(key)
        if hit is not None and all(os.path.exists(p) for p in outputs):
            with _cache_lock:
                self.cached += 1
            return hit["doc"], hit["seconds"]
        start = time.perf_counter()
        proc = subprocess.run(args, capture_output=True, text=True)
        seconds = time.perf_counter() - start
        if proc.returncode != 0:
            fail(f"{os.path.basename(exe)} failed ({proc.returncode}): {' '.join(args[1:])}: {proc.stderr.strip()}")
        doc = json.loads(proc.stdout) if capture_json else None
        with _cache_lock:
            self.runs += 1
            self.cache[key] = {"doc": doc, "seconds": seconds, "args": [os.path.basename(args[0])] + args[1:]}
        return doc, seconds

    def save(self):
        with _cache_lock:
            with open(self.path + ".tmp", "w") as f:
                json.dump(self.cache, f)
            os.replace(self.path + ".tmp", self.path)


def read_exr(path):
    """The first channel of a scanline float/half EXR (uncompressed, ZIPS or ZIP, as the tools write it)
    as a flat list of floats in row order."""
    with open(path, "rb") as f:
        data = f.read()
    if struct.unpack_from("<I", data, 0)[0] != 20000630:
        fail(f"{path}: not an OpenEXR file")
    pos, header = 8, {}
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        end2 = data.index(b"\0", end + 1)
        (size,) = struct.unpack_from("<i", data, end2 + 1)
        header[name] = data[end2 + 5:end2 + 5 + size]
        pos = end2 + 5 + size
    pos += 1
    channels, c = [], header["channels"]
    i = 0
    while c[i] != 0:
        end = c.index(b"\0", i)
        (ptype,) = struct.unpack_from("<i", c, end + 1)
        channels.append((c[i:end].decode(), ptype))
        i = end + 17
    compression = header["compression"][0]
    if compression not in (0, 2, 3):
        fail(f"{path}: EXR compression {compression} is not read here")
    x0, y0, x1, y1 = struct.unpack("<iiii", header["dataWindow"])
    width, height = x1 - x0 + 1, y1 - y0 + 1
    lines = 16 if compression == 3 else 1
    blocks = (height + lines - 1) // lines
    offsets = struct.unpack_from(f"<{blocks}Q", data, pos)
    sizes = {1: 2, 2: 4, 0: 4}
    values = []
    for off in sorted(offsets, key=lambda o: struct.unpack_from("<i", data, o)[0]):
        y, size = struct.unpack_from("<ii", data, off)
        raw = data[off + 8:off + 8 + size]
        n_lines = min(lines, y1 + 1 - y)
        expected = n_lines * width * sum(sizes[t] for _, t in channels)
        if compression != 0 and size < expected:
            t = bytearray(zlib.decompress(raw))
            for k in range(1, len(t)):
                t[k] = (t[k - 1] + t[k] - 128) & 0xFF
            half = (len(t) + 1) // 2
            out = bytearray(len(t))
            out[0::2] = t[:half]
            out[1::2] = t[half:]
            raw = bytes(out)
        p = 0
        for _ in range(n_lines):
            for k, (_, ptype) in enumerate(channels):
                count = width * sizes[ptype]
                if k == 0:
                    code = {1: "e", 2: "f"}.get(ptype)
                    if code is None:
                        fail(f"{path}: EXR channel type {ptype} is not read here")
                    values.extend(struct.unpack_from(f"<{width}{code}", raw, p))
                p += count
    return values


def relative_l1(a, ref):
    total = sum(ref)
    if len(a) != len(ref) or total <= 0:
        return None
    return sum(abs(x - r) for x, r in zip(a, ref)) / total


def median(values):
    v = sorted(x for x in values if x is not None)
    if not v:
        return None
    n = len(v)
    return v[n // 2] if n % 2 else 0.5 * (v[n // 2 - 1] + v[n // 2])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bin", default=os.path.join(ROOT, "build", "bin"), help="directory of the tools")
    parser.add_argument("--maps", default=os.path.join(ROOT, "examples", "out", "maps"), help="example maps")
    parser.add_argument("--out", default=os.path.join(ROOT, "out", "report"), help="report directory")
    parser.add_argument("--scenes", default=os.path.join(ROOT, "examples", "scenes"), help="scene files")
    parser.add_argument("--real-dir", default=os.path.join(ROOT, "..", "shared", "data", "normalmaps"),
                        help="folder of real normal maps (used when it exists)")
    parser.add_argument("--no-real", action="store_true", help="leave out the real maps")
    parser.add_argument("--only", action="append", choices=sorted(MAPS) + sorted(REAL_MAPS),
                        help="render only these maps")
    parser.add_argument("--image-size", help="override the scenes' image size, W,H in pixels")
    parser.add_argument("--views", default=",".join(VIEWS), help="views (scene names plane_VIEW.json)")
    parser.add_argument("--ndf-sigmas", default=",".join(f"{s:g}" for s in NDF_SIGMAS),
                        help="footprints (texels) of the NDF image comparison")
    parser.add_argument("--show-sigmas", default=",".join(f"{s:g}" for s in SHOW_SIGMAS),
                        help="footprints whose NDF images are shown side by side (a subset of --ndf-sigmas)")
    parser.add_argument("--no-glitter", action="store_true", help="leave out the procedural glitter renders")
    parser.add_argument("--no-wang", action="store_true", help="leave out the Wang tile renders")
    parser.add_argument("--no-tiny", action="store_true", help="leave out the tiny-example renders")
    parser.add_argument("-j", "--jobs", type=int, default=2, help="tool runs in parallel (each on one thread)")
    opts = parser.parse_args()
    views = [v for v in opts.views.split(",") if v]
    ndf_sigmas = [float(s) for s in opts.ndf_sigmas.split(",") if s]
    show_sigmas = [float(s) for s in opts.show_sigmas.split(",") if s]
    if not set(show_sigmas) <= set(ndf_sigmas):
        fail("--show-sigmas must be a subset of --ndf-sigmas")

    total_start = time.perf_counter()
    cpu_start = os.times()
    for name in ("mapgen", "ndfgen", "tensorpack", "wangtile", "tinyexample", "glintref", "glintquery", "glintinfo"):
        if not os.access(os.path.join(opts.bin, name), os.X_OK):
            fail(f"{os.path.join(opts.bin, name)} not found: build first (scripts/build.sh) or pass --bin")
    out = opts.out
    work = os.path.join(out, "work")
    img_dir = os.path.join(out, "img")
    for d in (work, img_dir, opts.maps):
        os.makedirs(d, exist_ok=True)
    runner = Runner(opts.bin, work)
    tool = runner.tool
    threads = ["-j", "1"]

    real_dir = os.path.abspath(opts.real_dir)
    real_present = os.path.isdir(real_dir) and not opts.no_real
    maps = []  # (name, kind, source)
    for name in MAPS:
        if not opts.only or name in opts.only:
            maps.append((name, "procedural", MAPS[name]))
    missing_real = []
    if real_present:
        for name, file in REAL_MAPS.items():
            if opts.only and name not in opts.only:
                continue
            if os.path.exists(os.path.join(real_dir, file)):
                maps.append((name, "real", file))
            else:
                missing_real.append(file)
    if not maps:
        fail("no maps to render")
    assets_dir = os.path.dirname(os.path.abspath(opts.maps))

    def prepare(entry):
        """The map (generated or cropped), its two assets and its whole-map NDF asset."""
        name, kind, source = entry
        print(f"make-report: {name}: bake", file=sys.stderr)
        info = {"map": name, "kind": kind}
        if kind == "procedural":
            map_path = os.path.join(opts.maps, f"{name}.exr")
            if not os.path.exists(map_path):
                runner.run([tool("mapgen")] + source + ["-o", map_path, "--quiet"], outputs=[map_path])
            info["source"] = "mapgen " + " ".join(source)
        else:
            src = os.path.join(real_dir, source)
            map_path = os.path.join(work, f"{name}.png")
            probe = subprocess.run(["oiiotool", "--info", src], capture_output=True, text=True)
            try:
                dims = probe.stdout.split(":", 1)[1].split(",")[0].split("x")
                w, h = int(dims[0]), int(dims[1])
            except (IndexError, ValueError):
                fail(f"cannot read the size of {src}: {probe.stderr.strip()}")
            cw, ch = min(w, CROP), min(h, CROP)
            x0, y0 = (w - cw) // 2, (h - ch) // 2
            runner.run(["oiiotool", src, "--cut", f"{cw}x{ch}+{x0}+{y0}", "-o", map_path], inputs=[src],
                       outputs=[map_path])
            info["source"] = f"{source} ({w}x{h}), centre crop {cw}x{ch} at {x0},{y0}"
        info["map_path"] = map_path
        info["map_bytes"] = os.path.getsize(map_path)
        pyramid = os.path.join(assets_dir, "ndf", f"{name}.gbk")
        tensor = os.path.join(assets_dir, "tensor", f"{name}.gbk")
        if kind == "procedural" and all(os.path.exists(p) and os.path.getmtime(p) >= os.path.getmtime(map_path)
                                        for p in (pyramid, tensor)):
            info["baked_by"] = "examples/Makefile"
            info["pyramid"] = {"bake_seconds": None}
        else:
            info["baked_by"] = "make-report.py"
            pyramid = os.path.join(work, f"{name}_pyramid.gbk")
            _, s = runner.run([tool("ndfgen"), map_path, "-o", pyramid, "--quiet"], inputs=[map_path],
                              outputs=[pyramid])
            info["pyramid"] = {"bake_seconds": s}
            tensor = os.path.join(work, f"{name}_r16.gbk")
        pack, s = runner.run([tool("tensorpack"), "--rank", "16", map_path, "-o", tensor, "--json"],
                             inputs=[map_path], outputs=[tensor], capture_json=True) \
            if info["baked_by"] == "make-report.py" else (None, None)
        info["pyramid"].update({"path": pyramid, "bytes": os.path.getsize(pyramid)})
        info["tensor16"] = {"path": tensor, "bytes": os.path.getsize(tensor), "bake_seconds": s}
        if pack is not None:
            info["tensor16"].update({"raw_bytes": pack["raw_bytes"], "ratio": pack["ratio"],
                                     "relative_error": pack["relative_error"]})
        layout, _ = runner.run([tool("glintinfo"), "info", pyramid, "--json"], inputs=[pyramid], capture_json=True)
        levels = sum(1 for sec in layout["sections"] if sec["type_name"] == "ndf-level")
        info["pyramid"]["levels"] = levels
        info["pyramid"]["top_sigma"] = FLAKES_UP_TO * 2 ** (levels - 1)
        info["pyramid"]["flakes"] = any(sec["type_name"] == "flakes" for sec in layout["sections"])
        layout, _ = runner.run([tool("glintinfo"), "info", tensor, "--json"], inputs=[tensor], capture_json=True)
        info["tensor16"]["flakes"] = any(sec["type_name"] == "flakes" for sec in layout["sections"])
        # The whole map's NDF (what one smooth lobe gives): one footprint of half the map's side,
        # splatted from every flake (periodic: its weights vary by under 1% over the map).
        side = CROP if kind == "real" else int(source[source.index("--size") + 1])
        info["side"] = side
        whole = os.path.join(work, f"{name}_whole.gbk")
        runner.run([tool("ndfgen"), map_path, "-o", whole, "--sigma0", side / 2, "--stride", side, "--levels", 1,
                    "--no-flakes", "--quiet"] + threads, inputs=[map_path], outputs=[whole])
        info["whole"] = whole
        return info

    pool = concurrent.futures.ThreadPoolExecutor(max(1, opts.jobs))
    infos = list(pool.map(prepare, maps))

    def render_view(info, view):
        name = info["map"]
        scene = os.path.join(opts.scenes, f"plane_{view}.json")
        if not os.path.exists(scene):
            fail(f"{scene} not found")
        renders = {}
        for mode in MODES:
            stem = f"{name}_{view}_{mode}"
            exr = os.path.join(work, stem + ".exr")
            png = os.path.join(img_dir, stem + ".png")
            args = [tool("glintref"), "render", scene, "-o", exr, "--preview", png, "--exposure", EXPOSURE,
                    "--normal-map", info["map_path"], "--json", "--quiet"] + threads
            inputs = [scene, info["map_path"]]
            if opts.image_size:
                args += ["--image-size", opts.image_size]
            if mode in ("pyramid", "tensor16"):
                args += ["--ndf", "asset", "--asset", info[mode]["path"]]
                inputs.append(info[mode]["path"])
            else:
                args += ["--ndf", mode]
            outputs = [exr, png]
            if mode != "reference":  # MODES[0]: every other render is compared with it in its own run
                heat = os.path.join(img_dir, f"{name}_{view}_{mode}_error.png")
                args += ["--compare", renders["reference"]["exr"], "--heatmap", heat]
                inputs.append(renders["reference"]["exr"])
                outputs.append(heat)
            doc, _ = runner.run(args, inputs=inputs, outputs=outputs, capture_json=True)
            renders[mode] = {"render_seconds": doc["time_seconds"]["render"],
                             "sigma_mean": doc["footprint_sigma_texels"]["mean"],
                             "pixels_hit": doc["pixels_hit"],
                             "preview": os.path.relpath(png, out), "exr": exr}
            if mode != "reference":
                c, r = doc["compare"], renders[mode]
                ref_seconds = renders["reference"]["render_seconds"]
                r.update({"rmse": c["rmse"], "relative_mse": c["relative_mse"], "psnr": c["psnr"],
                          "heatmap": os.path.relpath(heat, out),
                          "speedup": ref_seconds / r["render_seconds"] if r["render_seconds"] > 0 else None})
        for r in renders.values():
            del r["exr"]
        return renders

    def ndf_at(info, sigma):
        """NDF images at one footprint: reference, both assets; relative L1 of each against it."""
        name, side = info["map"], info["side"]
        x, y = round(0.37 * side, 1) + 0.5, round(0.61 * side, 1) + 0.5
        stem = os.path.join(work, f"{name}_ndf_{sigma_name(sigma)}")
        ref_exr = stem + "_reference.exr"
        show = sigma in show_sigmas
        # Shown footprints also get PNGs, written by the run that evaluates the image; the assets' and
        # the whole map's at the reference's scale (1 / its maximum), so that the four compare.
        pngs = {m: os.path.join(img_dir, f"{name}_ndf_{sigma_name(sigma)}_{m}.png")
                for m in ("reference", "pyramid", "tensor16", "whole")}
        args = [tool("glintref"), "image", info["map_path"], "--at", f"{x},{y}", "--sigma", sigma, "--res", 128,
                "-o", ref_exr, "--json", "--quiet"] + threads
        if show:
            args += ["--preview", pngs["reference"]]
        ref_doc, ref_seconds = runner.run(args, inputs=[info["map_path"]],
                                          outputs=[ref_exr] + ([pngs["reference"]] if show else []), capture_json=True)
        ref = read_exr(ref_exr)
        result = {"sigma": sigma, "at": [x, y], "reference_seconds": ref_seconds, "lobes": ref_doc["lobes"]}
        scale = 1.0 / ref_doc["max"] if ref_doc["max"] > 0 else 1.0
        if show:
            result["reference_png"] = os.path.relpath(pngs["reference"], out)
        whole_pfm = os.path.join(work, f"{name}_whole.exr")
        for mode, asset, at_sigma, exr in (("pyramid", info["pyramid"]["path"], sigma, f"{stem}_pyramid.exr"),
                                           ("tensor16", info["tensor16"]["path"], sigma, f"{stem}_tensor16.exr"),
                                           ("whole", info["whole"], side / 2, whole_pfm)):
            args = [tool("glintquery"), "image", asset, "--at", f"{x},{y}", "--sigma", at_sigma, "-o", exr,
                    "--quiet"] + threads
            if show:
                args += ["--preview", pngs[mode], "--preview-scale", repr(scale)]
            runner.run(args, inputs=[asset], outputs=[exr] + ([pngs[mode]] if show else []))
            key = "whole_map" if mode == "whole" else mode
            result[key] = relative_l1(read_exr(exr), ref)
            if show:
                result[mode + "_png"] = os.path.relpath(pngs[mode], out)
        return result

    def glitter_asset():
        """The example build's glitter asset when it is there, else the same surface baked here."""
        made = os.path.join(assets_dir, "glitter", "glitter_asset.gbk")
        if os.path.exists(made):
            return made, "examples/Makefile"
        path = os.path.join(work, "glitter_asset.gbk")
        runner.run([tool("ndfgen")] + GLITTER_ARGS + ["-o", path, "--quiet"], outputs=[path])
        return path, "make-report.py"

    def render_glitter(asset, view):
        """One distance: the glitter asset and the smooth Beckmann BRDF; the glitter render against the
        smooth one (relative MSE) and the spread of their per-pixel ratio (sparkle contrast)."""
        scene = os.path.join(opts.scenes, f"glitter_{view}.json")
        if not os.path.exists(scene):
            fail(f"{scene} not found")
        renders = {}
        for mode in ("smooth", "glitter"):  # the glitter render is compared with the smooth one in its run
            stem = f"glitter_{view}_{mode}"
            exr = os.path.join(work, stem + ".exr")
            png = os.path.join(img_dir, stem + ".png")
            args = [tool("glintref"), "render", scene, "-o", exr, "--preview", png, "--exposure", EXPOSURE,
                    "--asset", asset, "--ndf", "asset" if mode == "glitter" else "smooth", "--json",
                    "--quiet"] + threads
            inputs = [scene, asset]
            if mode == "glitter":
                args += ["--compare", renders["smooth"]["exr"]]
                inputs.append(renders["smooth"]["exr"])
            if opts.image_size:
                args += ["--image-size", opts.image_size]
            doc, _ = runner.run(args, inputs=inputs, outputs=[exr, png], capture_json=True)
            renders[mode] = {"render_seconds": doc["time_seconds"]["render"],
                             "sigma_mean": doc["footprint_sigma_texels"]["mean"],
                             "pixels_hit": doc["pixels_hit"], "mean_radiance": doc["mean_radiance"],
                             "preview": os.path.relpath(png, out), "exr": exr}
            if mode == "glitter":
                vs_smooth = doc["compare"]
        glitter, smooth = read_exr(renders["glitter"]["exr"]), read_exr(renders["smooth"]["exr"])
        floor = 0.05 * max(smooth) if smooth else 0.0
        ratios = [g / s for g, s in zip(glitter, smooth) if s > floor]
        mean = sum(ratios) / len(ratios) if ratios else None
        contrast = (math.sqrt(sum((r - mean) ** 2 for r in ratios) / len(ratios)) / mean) if mean else None
        result = {"view": view, "sigma_mean": renders["glitter"]["sigma_mean"],
                  "pixels_hit": renders["glitter"]["pixels_hit"],
                  "relative_mse_vs_smooth": vs_smooth["relative_mse"], "psnr_vs_smooth": vs_smooth["psnr"],
                  "mean_ratio": mean, "sparkle_contrast": contrast,
                  "facets_per_pixel": GLITTER_FACETS_PER_TEXEL * 4 * math.pi * renders["glitter"]["sigma_mean"] ** 2}
        for mode, r in renders.items():
            del r["exr"]
            result[mode] = r
        return result

    def wang_assets():
        """The scratches map, its tensor asset and tile set (the example build's when up to date), and
        the materialised grid region the tile set covers in the renders."""
        map_path = os.path.join(opts.maps, "scratches.exr")
        if not os.path.exists(map_path):
            runner.run([tool("mapgen")] + MAPS["scratches"] + ["-o", map_path, "--quiet"], outputs=[map_path])
        made = {"tensor": os.path.join(assets_dir, "tensor", "scratches.gbk"),
                "wang": os.path.join(assets_dir, "wang", "scratches.gbk")}
        paths, baked_by = {}, "examples/Makefile"
        for key, path in made.items():
            if os.path.exists(path) and os.path.getmtime(path) >= os.path.getmtime(map_path):
                paths[key] = path
                continue
            baked_by = "make-report.py"
            paths[key] = os.path.join(work, f"scratches_{key}.gbk")
            args = ([tool("tensorpack"), "--rank", "16", map_path] if key == "tensor" else
                    [tool("wangtile"), map_path] + WANG_BAKE)
            runner.run(args + ["-o", paths[key], "--quiet"], inputs=[map_path], outputs=[paths[key]])
        paths["map"] = map_path
        paths["region"] = os.path.join(work, "wang_region.exr")
        runner.run([tool("glintquery"), "materialise", paths["wang"], "--cells", WANG_CELLS, "-o", paths["region"],
                    "--quiet"], inputs=[paths["wang"]], outputs=[paths["region"]])
        return paths, baked_by

    def render_wang(paths):
        """The tile set, the repeated example and the reference on the materialised region; each against
        the reference, and how strongly each render repeats at the example's period."""
        renders = {}
        for mode in ("reference", "tiled", "repeated"):  # each asset render is compared with the reference in its run
            scene = os.path.join(opts.scenes, f"wang_{mode}.json")
            if not os.path.exists(scene):
                fail(f"{scene} not found")
            exr = os.path.join(work, f"wang_{mode}.exr")
            png = os.path.join(img_dir, f"wang_{mode}.png")
            args = [tool("glintref"), "render", scene, "-o", exr, "--preview", png, "--exposure", EXPOSURE, "--json",
                    "--quiet"] + threads
            inputs = [scene]
            if mode == "tiled":
                args += ["--ndf", "asset", "--asset", paths["wang"]]
                inputs.append(paths["wang"])
            elif mode == "repeated":
                args += ["--ndf", "asset", "--asset", paths["tensor"], "--normal-map", paths["map"]]
                inputs += [paths["tensor"], paths["map"]]
            else:
                args += ["--ndf", "reference", "--normal-map", paths["region"]]
                inputs.append(paths["region"])
            if mode != "reference":
                args += ["--compare", renders["reference"]["exr"]]
                inputs.append(renders["reference"]["exr"])
            if opts.image_size:
                args += ["--image-size", opts.image_size]
            doc, _ = runner.run(args, inputs=inputs, outputs=[exr, png], capture_json=True)
            renders[mode] = {"render_seconds": doc["time_seconds"]["render"],
                             "sigma_mean": doc["footprint_sigma_texels"]["mean"], "width": doc["width"],
                             "height": doc["height"], "preview": os.path.relpath(png, out), "exr": exr}
            if mode != "reference":
                renders[mode]["relative_mse_vs_reference"] = doc["compare"]["relative_mse"]
        period = max(1, renders["tiled"]["width"] // WANG_REPEATS)
        for r in renders.values():
            r["repetition"] = period_correlation(read_exr(r["exr"]), r["width"], r["height"], period)
            del r["exr"]
        return {"period_pixels": period, "cells": WANG_CELLS, "renders": renders}

    def tiny_assets():
        """Both tiny-example assets of the brushed crop (baked here with the example build's arguments,
        for their figures) and, per view, the region of each plane the scene shows as a normal map."""
        map_path = os.path.join(opts.maps, f"{TINY_MAP}.exr")
        if not os.path.exists(map_path):
            runner.run([tool("mapgen")] + MAPS[TINY_MAP] + ["-o", map_path, "--quiet"], outputs=[map_path])
        assets = {}
        for kind, args in TINY_BAKE.items():
            path = os.path.join(work, f"tiny_{kind}.gbk")
            doc, seconds = runner.run([tool("tinyexample"), map_path] + args + ["-o", path, "--json", "-j", "1"],
                                      inputs=[map_path], outputs=[path], capture_json=True)
            regions = {}
            for view, cells in TINY_VIEWS.items():
                region = os.path.join(work, f"tiny_{kind}_{view}_region.exr")
                made, _ = runner.run([tool("glintquery"), "materialise", path, "--cells", f"0,0,{cells},{cells}",
                                      "-o", region, "--json"], inputs=[path], outputs=[region], capture_json=True)
                regions[view] = {"path": region, "covered_fraction": made["covered_fraction"]}
            assets[kind] = {"path": path, "regions": regions, "bake": " ".join(args),
                            "bake_seconds": seconds, "tile_seconds": doc["tile_seconds"],
                            "file_bytes": doc["file_bytes"], "raw_bytes": doc["raw_bytes"], "tiles": doc["tiles"],
                            "flakes": doc["flakes"], "covered_fraction": doc["asset"].get("covered_fraction")}
        return assets

    def render_tiny(asset, kind, view):
        """One asset at one distance: the runtime's render and the reference's on the materialised
        region, their relative MSE and the fraction of the region's texels some example covers."""
        renders = {}
        heat = os.path.join(img_dir, f"tiny_{kind}_{view}_error.png")
        for mode in ("reference", "asset"):  # the asset's render is compared with the reference in its run
            scene = os.path.join(opts.scenes, f"tiny_{view}.json" if mode == "asset" else f"tiny_{view}_reference.json")
            if not os.path.exists(scene):
                fail(f"{scene} not found")
            stem = f"tiny_{kind}_{view}_{mode}"
            exr = os.path.join(work, stem + ".exr")
            png = os.path.join(img_dir, stem + ".png")
            args = [tool("glintref"), "render", scene, "-o", exr, "--preview", png, "--exposure", EXPOSURE, "--json",
                    "--quiet"] + threads
            inputs = [scene]
            outputs = [exr, png]
            if mode == "asset":
                args += ["--ndf", "asset", "--asset", asset["path"], "--compare", renders["reference"]["exr"],
                         "--heatmap", heat]
                inputs += [asset["path"], renders["reference"]["exr"]]
                outputs.append(heat)
            else:
                args += ["--ndf", "reference", "--normal-map", asset["regions"][view]["path"]]
                inputs.append(asset["regions"][view]["path"])
            if opts.image_size:
                args += ["--image-size", opts.image_size]
            doc, _ = runner.run(args, inputs=inputs, outputs=outputs, capture_json=True)
            renders[mode] = {"render_seconds": doc["time_seconds"]["render"],
                             "sigma_mean": doc["footprint_sigma_texels"]["mean"],
                             "preview": os.path.relpath(png, out), "exr": exr}
            if mode == "asset":
                vs_reference = doc["compare"]
        # The NDF images at the region's centre and the view's footprint: the asset's bin averages
        # against the reference evaluator's on the materialised map.
        centre = TINY_VIEWS[view] * 16 + 0.5
        sigma = round(renders["asset"]["sigma_mean"], 2)
        at = f"{centre},{centre + 30}"
        ref_exr = os.path.join(work, f"tiny_{kind}_{view}_ndf_reference.exr")
        runner.run([tool("glintref"), "image", asset["regions"][view]["path"], "--at", at, "--sigma", sigma, "--res",
                    128, "-o", ref_exr, "--quiet"] + threads, inputs=[asset["regions"][view]["path"]],
                   outputs=[ref_exr])
        asset_exr = os.path.join(work, f"tiny_{kind}_{view}_ndf_asset.exr")
        runner.run([tool("glintquery"), "image", asset["path"], "--at", at, "--sigma", sigma, "-o", asset_exr,
                    "--quiet"] + threads, inputs=[asset["path"]], outputs=[asset_exr])
        result = {"type": kind, "view": view, "examples_across": TINY_VIEWS[view],
                  "ndf_relative_l1": relative_l1(read_exr(asset_exr), read_exr(ref_exr)), "ndf_at": at,
                  "sigma_mean": renders["asset"]["sigma_mean"], "relative_mse": vs_reference["relative_mse"],
                  "psnr": vs_reference["psnr"], "heatmap": os.path.relpath(heat, out),
                  "covered_texels": asset["regions"][view]["covered_fraction"],
                  "speedup": (renders["reference"]["render_seconds"] / renders["asset"]["render_seconds"]
                              if renders["asset"]["render_seconds"] > 0 else None)}
        for mode, r in renders.items():
            del r["exr"]
            result[mode] = r
        return result

    tasks = []
    wang_task = None
    if not opts.no_wang:
        wang_paths, wang_by = wang_assets()
        wang_task = pool.submit(render_wang, wang_paths)
    tiny_tasks, tiny = [], None
    if not opts.no_tiny:
        tiny = tiny_assets()
        tiny_tasks = [pool.submit(render_tiny, tiny[kind], kind, view) for kind in TINY_BAKE for view in TINY_VIEWS]
    glitter_tasks = []
    if not opts.no_glitter:
        asset, glitter_by = glitter_asset()
        glitter_tasks = [pool.submit(render_glitter, asset, view) for view in GLITTER_VIEWS]
    for info in infos:
        for view in views:
            tasks.append(("render", info, view, pool.submit(render_view, info, view)))
        for sigma in ndf_sigmas:
            tasks.append(("ndf", info, sigma, pool.submit(ndf_at, info, sigma)))
    report = {"views": views, "modes": MODES, "ndf_sigmas": ndf_sigmas, "show_sigmas": show_sigmas,
              "real_maps": {"dir": os.path.relpath(real_dir, ROOT), "present": real_present,
                            "missing": missing_real, "crop": CROP, "left_out": opts.no_real},
              "paths": {"flakes_up_to": FLAKES_UP_TO, "handover_up_to": HANDOVER_UP_TO},
              "assets": []}
    for info in infos:
        entry = {k: v for k, v in info.items() if k not in ("map_path", "whole")}
        for mode in ("pyramid", "tensor16"):
            entry[mode] = {k: v for k, v in info[mode].items() if k != "path"}
        entry["renders"] = {}
        entry["ndf"] = []
        report["assets"].append(entry)
    for kind, info, what, future in tasks:
        entry = next(e for e in report["assets"] if e["map"] == info["map"])
        if kind == "render":
            entry["renders"][what] = future.result()
            print(f"make-report: {info['map']}: view {what}", file=sys.stderr)
        else:
            entry["ndf"].append(future.result())
    if wang_task is not None:
        report["wang"] = wang_task.result()
        report["wang"]["baked_by"] = wang_by
        print("make-report: wang tiles: repetition " + " ".join(
            f"{m} {fmt(r['repetition'])}" for m, r in report["wang"]["renders"].items()), file=sys.stderr)
    if tiny_tasks:
        report["tiny"] = {"map": TINY_MAP, "assets": {k: {key: v for key, v in a.items() if key not in ("path", "regions")}
                                                      for k, a in tiny.items()},
                          "views": [t.result() for t in tiny_tasks]}
        print("make-report: tiny examples: relative MSE " + " ".join(
            f"{v['type']}/{v['view']} {fmt(v['relative_mse'])}" for v in report["tiny"]["views"]), file=sys.stderr)
    if glitter_tasks:
        report["glitter"] = {"baked_by": glitter_by, "bake": " ".join(GLITTER_ARGS),
                             "views": [t.result() for t in glitter_tasks]}
        print("make-report: glitter: " + " ".join(
            f"{v['view']} contrast {fmt(v['sparkle_contrast'])}" for v in report["glitter"]["views"]), file=sys.stderr)
    pool.shutdown()
    runner.save()

    plot_dir = img_dir
    for entry in report["assets"]:
        svg = os.path.join(plot_dir, f"{entry['map']}_ndf_l1.svg")
        write_plot(svg, entry)
        entry["ndf_plot"] = os.path.relpath(svg, out)
    summary = os.path.join(plot_dir, "ndf_l1_median.svg")
    med = {"map": "median over the maps", "pyramid": {"top_sigma": None}, "ndf": []}
    for sigma in ndf_sigmas:
        row = {"sigma": sigma}
        for key in ("pyramid", "tensor16", "whole_map"):
            row[key] = median(r[key] for e in report["assets"] for r in e["ndf"] if r["sigma"] == sigma)
        med["ndf"].append(row)
    write_plot(summary, med)
    report["ndf_median"] = med["ndf"]
    report["ndf_median_plot"] = os.path.relpath(summary, out)
    report["total_seconds"] = time.perf_counter() - total_start
    cpu_end = os.times()
    report["tool_cpu_seconds"] = (cpu_end.children_user - cpu_start.children_user) + (cpu_end.children_system -
                                                                                    cpu_start.children_system)
    report["tool_runs"] = runner.runs
    report["cached_runs"] = runner.cached

    with open(os.path.join(out, "report.json"), "w") as f:
        json.dump(report, f, indent=2)
    write_html(os.path.join(out, "index.html"), report)
    print(f"make-report: wrote {os.path.join(out, 'index.html')} ({report['total_seconds']:.1f} s wall, "
          f"{report['tool_cpu_seconds']:.1f} s tool CPU, {runner.runs} runs, {runner.cached} cached)", file=sys.stderr)
    if not real_present:
        reason = "--no-real" if opts.no_real else f"{real_dir} is absent"
        print(f"make-report: no real maps ({reason})", file=sys.stderr)
    for entry in report["assets"]:
        figures = " ".join(f"{v}:{fmt(entry['renders'][v]['pyramid']['relative_mse'])}/"
                           f"{fmt(entry['renders'][v]['tensor16']['relative_mse'])}/"
                           f"{fmt(entry['renders'][v]['smooth']['relative_mse'])}" for v in views)
        print(f"  {entry['map']:22s} relative MSE pyramid/tensor16/smooth: {figures}", file=sys.stderr)


def period_correlation(values, width, height, period):
    """How much an image repeats at `period` pixels: the correlation of its detail (the image less its
    local mean over a window of about period / 4) with itself shifted by the period, along x and y,
    averaged. About 1 for a surface repeated at that period, small for one that does not repeat."""
    r = max(1, period // 8)
    sums = [[0.0] * (width + 1) for _ in range(height + 1)]
    for y in range(height):
        row = 0.0
        for x in range(width):
            row += values[y * width + x]
            sums[y + 1][x + 1] = sums[y][x + 1] + row
    detail = []
    for y in range(height):
        y0, y1 = max(0, y - r), min(height, y + r + 1)
        for x in range(width):
            x0, x1 = max(0, x - r), min(width, x + r + 1)
            mean = (sums[y1][x1] - sums[y0][x1] - sums[y1][x0] + sums[y0][x0]) / ((y1 - y0) * (x1 - x0))
            detail.append(values[y * width + x] - mean)
    result = []
    for dx, dy in ((period, 0), (0, period)):
        a = [detail[y * width + x] for y in range(height - dy) for x in range(width - dx)]
        b = [detail[(y + dy) * width + x + dx] for y in range(height - dy) for x in range(width - dx)]
        if not a:
            return None
        ma, mb = sum(a) / len(a), sum(b) / len(b)
        va = sum((p - ma) ** 2 for p in a)
        vb = sum((q - mb) ** 2 for q in b)
        if va <= 0 or vb <= 0:
            return None
        result.append(sum((p - ma) * (q - mb) for p, q in zip(a, b)) / math.sqrt(va * vb))
    return sum(result) / len(result)


def write_plot(path, entry):
    """NDF relative L1 against the footprint (log axis) per asset, the whole-map NDF as baseline."""
    width, height, left, right, top, bottom = 460, 280, 52, 128, 26, 40
    rows = entry["ndf"]
    sigmas = [r["sigma"] for r in rows]
    lo, hi = math.log2(min(sigmas) / 1.2), math.log2(max(max(sigmas) * 1.2, 90.0))
    values = [r[k] for r in rows for k in ("pyramid", "tensor16", "whole_map") if r.get(k) is not None]
    ymax = max(0.5, math.ceil(min(max(values + [0.5]), 3.0) * 4) / 4)
    px = lambda s: left + (math.log2(s) - lo) / (hi - lo) * (width - left - right)
    py = lambda v: top + (1 - min(v, ymax) / ymax) * (height - top - bottom)
    e = html.escape
    parts = [f"<svg xmlns='http://www.w3.org/2000/svg' width='{width}' height='{height}' "
             f"viewBox='0 0 {width} {height}' font-family='sans-serif' font-size='11'>",
             f"<rect width='{width}' height='{height}' fill='white'/>",
             f"<text x='{left}' y='15' font-size='12'>{e(entry['map'])}: NDF relative L1 vs footprint</text>"]
    bands = [(2 ** lo, FLAKES_UP_TO, "#e8f4e8", "flakes"), (FLAKES_UP_TO, HANDOVER_UP_TO, "#fff2d6", "blend"),
             (HANDOVER_UP_TO, 2 ** hi, "#eef0fa", "pyramid")]
    top_sigma = entry["pyramid"].get("top_sigma")
    if top_sigma and top_sigma < 2 ** hi:
        bands[-1] = (HANDOVER_UP_TO, top_sigma, "#eef0fa", "pyramid")
        bands.append((top_sigma, 2 ** hi, "#f4e8f0", "clamp"))
    for a, b, colour, label in bands:
        parts.append(f"<rect x='{px(a):.1f}' y='{top}' width='{px(b) - px(a):.1f}' height='{height - top - bottom}' "
                     f"fill='{colour}'/>")
        if px(b) - px(a) >= 6 * len(label):
            parts.append(f"<text x='{px(a) + 2:.1f}' y='{top + 11}' fill='#666'>{label}</text>")
    for i in range(5):
        v = ymax * i / 4
        parts.append(f"<line x1='{left}' x2='{width - right}' y1='{py(v):.1f}' y2='{py(v):.1f}' stroke='#ccc'/>"
                     f"<text x='{left - 4}' y='{py(v) + 4:.1f}' text-anchor='end'>{v:g}</text>")
    for s in (0.5, 1, 2, 4, 8, 16, 32, 64):
        if 2 ** lo <= s <= 2 ** hi:
            parts.append(f"<line x1='{px(s):.1f}' x2='{px(s):.1f}' y1='{height - bottom}' y2='{height - bottom + 4}' "
                         f"stroke='#000'/><text x='{px(s):.1f}' y='{height - bottom + 15}' "
                         f"text-anchor='middle'>{s:g}</text>")
    parts.append(f"<text x='{(left + width - right) / 2:.1f}' y='{height - 6}' text-anchor='middle'>"
                 "footprint sigma (texels)</text>")
    parts.append(f"<rect x='{left}' y='{top}' width='{width - left - right}' height='{height - top - bottom}' "
                 "fill='none' stroke='#000'/>")
    series = [("pyramid", "#1f5fbf", "", "ndf-pyramid"), ("tensor16", "#c0392b", "", "tensor rank 16"),
              ("whole_map", "#555", "5,4", "whole-map NDF")]
    for i, (key, colour, dash, label) in enumerate(series):
        pts = [(px(r["sigma"]), py(r[key])) for r in rows if r.get(key) is not None]
        if pts:
            path_d = " ".join(f"{'M' if j == 0 else 'L'}{x:.1f},{y:.1f}" for j, (x, y) in enumerate(pts))
            parts.append(f"<path d='{path_d}' fill='none' stroke='{colour}' stroke-width='2'"
                         + (f" stroke-dasharray='{dash}'" if dash else "") + "/>")
            for x, y in pts:
                parts.append(f"<circle cx='{x:.1f}' cy='{y:.1f}' r='2.5' fill='{colour}'/>")
        ly = top + 14 + 16 * i
        parts.append(f"<line x1='{width - right + 8}' x2='{width - right + 28}' y1='{ly}' y2='{ly}' stroke='{colour}' "
                     "stroke-width='2'" + (f" stroke-dasharray='{dash}'" if dash else "") + "/>"
                     f"<text x='{width - right + 32}' y='{ly + 4}'>{label}</text>")
    parts.append("</svg>\n")
    with open(path + ".tmp", "w") as f:
        f.write("".join(parts))
    os.replace(path + ".tmp", path)


def wang_html(wang):
    """The Wang tile section: the tiled plane beside the repeated example and the reference."""
    e = html.escape
    r = wang["renders"]
    titles = {"tiled": "wang-tiles asset (runtime)", "repeated": "the example repeated (tensor asset)",
              "reference": "reference P-NDF of the materialised region"}
    parts = [f"""<h2 id='wang'>Wang tiles: an unbounded surface far away</h2>
<p>A complete 16-tile Wang set cut from the scratches map (<code>wangtile {e(' '.join(WANG_BAKE))}</code>, baked by
{e(wang['baked_by'])}) on a plane 32 x 32 tiles across, seen from straight above by a distant narrow camera
under one directional light, beside the scratches example itself repeated 8 x 8 times over the same plane
and the reference P-NDF of the same region of the implicit grid (<code>glintquery materialise --cells
{e(wang['cells'])}</code>). Repetition = correlation of each render's detail with itself shifted by the
example's period ({wang['period_pixels']} pixels), along x and y: near 1 when the surface visibly repeats.</p>
<table>
<tr><th class='l'>render</th><th>footprint std (texels)</th><th>repetition at the example's period</th>
<th>relative MSE vs the reference</th><th>render time (s)</th></tr>
"""]
    for mode in ("tiled", "repeated", "reference"):
        v = r[mode]
        parts.append(f"<tr><td class='l'>{e(titles[mode])}</td><td>{fmt(v['sigma_mean'])}</td>"
                     f"<td>{fmt(v['repetition'])}</td><td>{fmt(v.get('relative_mse_vs_reference'))}</td>"
                     f"<td>{fmt(v['render_seconds'])}</td></tr>\n")
    parts.append("</table>\n<div class='row'>")
    for mode in ("tiled", "repeated", "reference"):
        parts.append(f"<figure><img src='{e(r[mode]['preview'])}' alt='{e(titles[mode])}'>"
                     f"<figcaption>{e(titles[mode])}</figcaption></figure>\n")
    parts.append("</div>\n")
    return "".join(parts)


def tiny_html(tiny):
    """The tiny-example section: each asset near and far beside the reference on its materialised plane."""
    e = html.escape
    parts = [f"""<h2 id='tiny'>Tiny examples: one 32 x 32 crop over the whole plane</h2>
<p>Two tiny-example assets (Xing et al.) of a 32 x 32 crop of the {e(tiny['map'])} map: tiled (one
transform for all copies, here a rotation by 90 degrees) and stochastic (each example rotated and
scaled at random, a given fraction of the plane covered, the rest flat). Each is rendered through the
runtime on a plane seen from straight above under one directional light, near (8 x 8 examples across)
and far (64 x 64), beside the reference P-NDF of the same region of the asset's plane materialised as a
normal map (<code>glintquery materialise</code>: every example as placed and transformed, slopes
mapped by the inverse transpose as the runtime maps them). Relative MSE and heat maps as above;
covered texels: the fraction of the materialised region some example covers; NDF image relative L1:
the asset's NDF image (<code>glintquery image</code>, 128 x 128 bins) against the reference
evaluator's on the materialised region (<code>glintref image</code>) at the view's footprint, near
the region's centre. Both assets answer footprints below 4 texels exactly from the flakes of the plane
they lay (the rotated and rescaled examples as the materialised map holds them), blend them with the
tiles up to 6 texels and answer larger footprints from the tile images alone: piecewise constant over
bins 2/128 wide, so a render, which reads one half vector per pixel, shows the bins where the NDF is
as sharp as the brushed streak (the NDF images agree far better). Near, the stochastic render differs
from the reference only at the region's edges, where the reference repeats the region while the
plane goes on.</p>
<table>
<tr><th class='l'>asset</th><th class='l'>bake (tinyexample)</th><th>tiles</th><th>tile NDF time (s)</th>
<th>size (bytes)</th><th>raw tile images (bytes)</th><th>exact flakes</th><th>covered fraction asked</th></tr>
"""]
    for kind, a in tiny["assets"].items():
        parts.append(f"<tr><td class='l'>{e(kind)}</td><td class='l'><code>{e(a['bake'])}</code></td><td>{a['tiles']}</td>"
                     f"<td>{fmt(a['tile_seconds'])}</td><td>{a['file_bytes']}</td><td>{a['raw_bytes']}</td>"
                     f"<td>{'yes' if a['flakes'] else 'no'}</td><td>{fmt(a['covered_fraction'])}</td></tr>\n")
    parts.append("</table>\n<table>\n<tr><th class='l'>asset</th><th class='l'>view</th><th>examples across</th>"
                 "<th>footprint std (texels)</th><th>covered texels</th><th>relative MSE vs the reference</th>"
                 "<th>PSNR (dB)</th><th>NDF image relative L1</th><th>render time asset / reference (s)</th>"
                 "<th>speedup</th></tr>\n")
    for v in tiny["views"]:
        parts.append(f"<tr><td class='l'>{e(v['type'])}</td><td class='l'>{e(v['view'])}</td>"
                     f"<td>{v['examples_across']}</td><td>{fmt(v['sigma_mean'])}</td><td>{fmt(v['covered_texels'])}</td>"
                     f"<td>{fmt(v['relative_mse'])}</td><td>{fmt(v['psnr'])}</td><td>{fmt(v['ndf_relative_l1'])}</td>"
                     f"<td>{fmt(v['asset']['render_seconds'])} / {fmt(v['reference']['render_seconds'])}</td>"
                     f"<td>{fmt(v['speedup'])}</td></tr>\n")
    parts.append("</table>\n")
    for v in tiny["views"]:
        label = f"{v['type']}, {v['view']} (footprint {fmt(v['sigma_mean'])} texels)"
        parts.append(f"<div class='row'><h3>{e(label)}</h3>\n")
        for key, title in (("asset", "tiny-example asset (runtime)"),
                           ("reference", "reference P-NDF of the materialised region")):
            parts.append(f"<figure><img src='{e(v[key]['preview'])}' alt='{e(title)}'>"
                         f"<figcaption>{e(title)}</figcaption></figure>\n")
        parts.append(f"<figure><img src='{e(v['heatmap'])}' alt='error'><figcaption>error, relative MSE "
                     f"{fmt(v['relative_mse'])}</figcaption></figure>\n</div>\n")
    return "".join(parts)


def glitter_html(glitter):
    """The glitter section: three distances, glitter beside smooth Beckmann, with the figures."""
    e = html.escape
    parts = [f"""<h2 id='glitter'>Procedural glitter at three distances</h2>
<p>A glitter asset (<code>ndfgen {e(glitter['bake'])}</code>, baked by {e(glitter['baked_by'])}: discrete
stochastic microfacets, Jakob et al. 2014, no normal map) rendered through the runtime on a plane seen
from three distances, beside the smooth Beckmann BRDF of the same roughness. Near, a pixel sees a few
dozen facets and only some of them reflect the lights: sparkles. Far, it sees tens of thousands and
the glitter converges to the smooth BRDF. Sparkle contrast = standard deviation over the lit pixels of
the ratio glitter / smooth (one colour channel, pixels above 5% of the smooth render's maximum),
divided by its mean; the mean ratio stays near 1 (the facets carry the smooth NDF's energy).</p>
<table>
<tr><th class='l'>distance</th><th>footprint std (texels)</th><th>facets per pixel</th><th>pixels</th>
<th>sparkle contrast</th><th>mean ratio glitter / smooth</th><th>relative MSE vs smooth</th>
<th>render time glitter / smooth (s)</th></tr>
"""]
    for v in glitter["views"]:
        parts.append(f"<tr><td class='l'>{e(v['view'])}</td><td>{fmt(v['sigma_mean'])}</td>"
                     f"<td>{fmt(float(round(v['facets_per_pixel'])))}</td><td>{v['pixels_hit']}</td>"
                     f"<td>{fmt(v['sparkle_contrast'])}</td><td>{fmt(v['mean_ratio'])}</td>"
                     f"<td>{fmt(v['relative_mse_vs_smooth'])}</td><td>{fmt(v['glitter']['render_seconds'])} / "
                     f"{fmt(v['smooth']['render_seconds'])}</td></tr>\n")
    parts.append("</table>\n")
    for mode, title in (("glitter", "glitter asset"), ("smooth", "smooth Beckmann")):
        parts.append("<div class='row'>")
        for v in glitter["views"]:
            label = f"{title}, {v['view']} (footprint {fmt(v['sigma_mean'])} texels)"
            parts.append(f"<figure><img src='{e(v[mode]['preview'])}' alt='{e(label)}'>"
                         f"<figcaption>{e(label)}</figcaption></figure>\n")
        parts.append("</div>\n")
    return "".join(parts)


def write_html(path, report):
    e = html.escape
    views = report["views"]
    real = report["real_maps"]
    if real["present"]:
        real_text = (f"Real maps: centre crops ({real['crop']} x {real['crop']} texels) of normal maps in "
                     f"<code>{e(real['dir'])}</code>.")
        if real["missing"]:
            real_text += " Missing there: " + e(", ".join(real["missing"])) + "."
    else:
        why = "--no-real was given" if real.get("left_out") else f"<code>{e(real['dir'])}</code> is absent"
        real_text = f"<strong>No real maps in this report</strong>: {why}; only the procedural maps are shown."
    parts = ["""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>glintbake report</title>
<style>
body { font-family: sans-serif; margin: 1.5em; background: #fafafa; color: #222; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; }
th, td { border: 1px solid #bbb; padding: 0.25em 0.6em; text-align: right; }
th { background: #eee; }
td.l, th.l { text-align: left; }
figure { display: inline-block; margin: 0 0.4em 0.4em 0; text-align: center; vertical-align: top; }
figure img { width: 192px; height: 192px; image-rendering: pixelated; display: block; }
figure img.plot { width: 460px; height: 280px; image-rendering: auto; }
figcaption { font-size: 0.8em; }
.row { margin-bottom: 0.8em; }
</style>
</head>
<body>
<h1>glintbake report</h1>
"""]
    parts.append(f"""<p>Each map is rendered on a plane tile (10 x 10 world units, 5 x 5 repetitions of the map) seen
from six distances, 256 x 256 pixels, so that the pixel footprint (Gaussian std in texels, the mean
over the tile given per view) runs from 0.5 to 64 texels: the flakes path (below
{report['paths']['flakes_up_to']:g} texels: the asset answers exactly from the normal map's flakes), the
hand-over (blended into the pyramid up to {report['paths']['handover_up_to']:g}), the pyramid and its top
level. The tile keeps its size, so it covers fewer pixels as it recedes: the reference P-NDF costs in
proportion to the footprint's area per pixel, and this keeps every reference render bounded.
Modes: the reference P-NDF (exact, from the normal map), the baked assets through the runtime
(uncompressed ndf-pyramid, ndfgen defaults with flakes; tensor-ndf <code>tensorpack --rank 16</code>)
and a smooth GGX BRDF of the same base roughness. Errors are against the reference render:
relative MSE = sum((x - ref)^2) / sum(ref^2); heat maps show the per-pixel RMS error, red at 4 x
the image's RMSE. Previews are tone-mapped (exposure {EXPOSURE}, sRGB). {real_text}</p>
<p>NDF images (128 x 128 bins over s in [-1,1]^2) at one footprint centre per map: the reference
evaluator's bin averages (<code>glintref image</code>) against the assets' (<code>glintquery image</code>);
relative L1 = sum|A - R| / sum R over the image. The whole-map NDF (what one smooth lobe can at best
give) is one footprint of half the map's side splatted from every flake (ndfgen, one level).
Images are shown on one linear scale per footprint: the reference's maximum is white.</p>
""")
    # Summary: relative MSE per map, view and asset.
    parts.append("<h2 id='summary-mse'>Render relative MSE against the reference</h2>\n<table>\n"
                 "<tr><th class='l'>map</th><th class='l'>asset</th>")
    first = report["assets"][0]
    for v in views:
        parts.append(f"<th>{e(v)}<br>sigma {fmt(first['renders'][v]['reference']['sigma_mean'])}</th>")
    parts.append("</tr>\n")
    for entry in report["assets"]:
        for i, mode in enumerate(report["modes"][1:]):
            head = f"<td class='l' rowspan='3'>{e(entry['map'])}</td>" if i == 0 else ""
            cells = "".join(f"<td>{fmt(entry['renders'][v][mode].get('relative_mse'))}</td>" for v in views)
            parts.append(f"<tr>{head}<td class='l'>{e(MODE_TITLES[mode])}</td>{cells}</tr>\n")
    parts.append("</table>\n")
    parts.append("""<p>Above the flakes' range a render under a point light reads the P-NDF at one half vector per
pixel, while a pyramid level stores bin averages (bins 2/R wide in s, R = 128 here: 3.1 times the flakes'
intrinsic roughness sigma_r = 0.005) read as constant over each bin. Scratch maps concentrate much of
their mass on curves in s narrower than a bin, so at the far views a pixel's point value can lie far
above or below its bin's average even where the NDF images agree closely (next table): the large
relative MSE of the scratch maps at 24 and 64 texels is this angular resolution, not a wrong NDF.
Baked at R = 256 and 512, the curved-scratches crop renders at 0.17 and 0.037 (24 texels) and 0.072
and 0.005 (64 texels), at 4 and 16 times the storage (measured once; README, "Figures").
Area and environment lights integrate the NDF over s, where bin averages are what counts.</p>
""")
    # Summary: NDF L1 per sigma.
    parts.append("<h2 id='summary-ndf'>NDF relative L1 against the reference</h2>\n<table>\n"
                 "<tr><th class='l'>map</th><th class='l'>asset</th>")
    parts.append("".join(f"<th>{s:g}</th>" for s in report["ndf_sigmas"]) + "</tr>\n")
    rows = [(entry["map"], entry["ndf"]) for entry in report["assets"]] + [("median", report["ndf_median"])]
    for name, ndf in rows:
        for i, key in enumerate(("pyramid", "tensor16", "whole_map")):
            head = f"<td class='l' rowspan='3'>{e(name)}</td>" if i == 0 else ""
            label = {"pyramid": "ndf-pyramid", "tensor16": "tensor rank 16", "whole_map": "whole-map NDF"}[key]
            by_sigma = {r["sigma"]: r for r in ndf}
            cells = "".join(f"<td>{fmt(by_sigma[s].get(key))}</td>" for s in report["ndf_sigmas"])
            parts.append(f"<tr>{head}<td class='l'>{label}</td>{cells}</tr>\n")
    parts.append("</table>\n")
    parts.append(f"<figure><img class='plot' src='{e(report['ndf_median_plot'])}' alt='median NDF L1 plot'>"
                 "<figcaption>median over the maps</figcaption></figure>\n")
    parts.append(f"<p>Report time: {fmt(report['total_seconds'])} s wall, {fmt(report['tool_cpu_seconds'])} s of "
                 f"tool CPU ({report['tool_runs']} tool runs, {report['cached_runs']} answered from the cache).</p>\n")

    if report.get("wang"):
        parts.append(wang_html(report["wang"]))
    if report.get("glitter"):
        parts.append(glitter_html(report["glitter"]))
    if report.get("tiny"):
        parts.append(tiny_html(report["tiny"]))

    for entry in report["assets"]:
        t = entry["tensor16"]
        p = entry["pyramid"]
        parts.append(f"<h2 id='map-{e(entry['map'])}'>{e(entry['map'])}</h2>\n<p>{e(entry['kind'])}: "
                     f"{e(entry['source'])}; assets baked by {e(entry['baked_by'])}; pyramid levels "
                     f"{p['levels']} (top level sigma {fmt(p['top_sigma'])} texels); flakes section in the pyramid: "
                     f"{'yes' if p['flakes'] else 'no'}, in the tensor asset: "
                     f"{'yes' if t.get('flakes') else 'no (small footprints come from its level 0)'}.</p>\n")
        parts.append("<table>\n<tr><th class='l'>asset</th><th>bake time (s)</th><th>size (bytes)</th>"
                     "<th>ratio to raw float32 NDF images</th><th>CP relative error</th></tr>\n")
        raw = t.get("raw_bytes")
        parts.append(f"<tr><td class='l'>ndf-pyramid (ndfgen)</td><td>{fmt(p.get('bake_seconds'))}</td>"
                     f"<td>{p['bytes']}</td><td>{fmt(p['bytes'] / raw if raw else None)}</td><td>-</td></tr>\n")
        parts.append(f"<tr><td class='l'>tensor-ndf rank 16 (tensorpack)</td><td>{fmt(t.get('bake_seconds'))}</td>"
                     f"<td>{t['bytes']}</td><td>{fmt(t.get('ratio'))}</td><td>{fmt(t.get('relative_error'))}</td>"
                     "</tr>\n</table>\n")
        parts.append("<table>\n<tr><th class='l'>view</th><th>footprint std (texels)</th><th>pixels on the tile</th>"
                     "<th class='l'>mode</th><th>render time (s)</th><th>speedup over reference</th>"
                     "<th>relative MSE</th><th>PSNR (dB)</th></tr>\n")
        for v in views:
            renders = entry["renders"][v]
            n = len(report["modes"])
            for i, mode in enumerate(report["modes"]):
                r = renders[mode]
                head = (f"<td class='l' rowspan='{n}'>{e(v)}</td><td rowspan='{n}'>"
                        f"{fmt(renders['reference']['sigma_mean'])}</td><td rowspan='{n}'>"
                        f"{renders['reference']['pixels_hit']}</td>") if i == 0 else ""
                parts.append(f"<tr>{head}<td class='l'>{e(MODE_TITLES[mode])}</td><td>{fmt(r['render_seconds'])}</td>"
                             f"<td>{fmt(r.get('speedup'))}</td><td>{fmt(r.get('relative_mse'))}</td>"
                             f"<td>{fmt(r.get('psnr'))}</td></tr>\n")
        parts.append("</table>\n")
        for v in views:
            renders = entry["renders"][v]
            parts.append(f"<div class='row'><h3>{e(entry['map'])}, view {e(v)} (footprint "
                         f"{fmt(renders['reference']['sigma_mean'])} texels)</h3>\n")
            for mode in report["modes"]:
                parts.append(f"<figure><img src='{e(renders[mode]['preview'])}' alt='{e(mode)}'>"
                             f"<figcaption>{e(MODE_TITLES[mode])}</figcaption></figure>\n")
            for mode in report["modes"][1:]:
                parts.append(f"<figure><img src='{e(renders[mode]['heatmap'])}' alt='{e(mode)} error'>"
                             f"<figcaption>error: {e(MODE_TITLES[mode])}</figcaption></figure>\n")
            parts.append("</div>\n")
        parts.append(f"<h3>{e(entry['map'])}: NDF images</h3>\n")
        for r in entry["ndf"]:
            if "reference_png" not in r:
                continue
            parts.append(f"<div class='row ndf'><h4>sigma {r['sigma']:g} texels at {r['at'][0]:g},{r['at'][1]:g} "
                         f"({r['lobes']} lobes)</h4>\n")
            for key, label in (("reference_png", "reference (glintref image)"),
                               ("pyramid_png", f"ndf-pyramid, L1 {fmt(r['pyramid'])}"),
                               ("tensor16_png", f"tensor rank 16, L1 {fmt(r['tensor16'])}"),
                               ("whole_png", f"whole-map NDF, L1 {fmt(r['whole_map'])}")):
                parts.append(f"<figure><img src='{e(r[key])}' alt='{e(label)}'><figcaption>{e(label)}"
                             "</figcaption></figure>\n")
            parts.append("</div>\n")
        parts.append(f"<figure><img class='plot' src='{e(entry['ndf_plot'])}' alt='NDF L1 plot'>"
                     f"<figcaption>{e(entry['map'])}: NDF relative L1 against the footprint</figcaption></figure>\n")
    parts.append("""<script>
// Records how many images decoded, for the headless-browser test (tests/cli/test_report.py).
window.addEventListener("load", function () {
  var images = Array.prototype.slice.call(document.images);
  var loaded = images.filter(function (img) { return img.complete && img.naturalWidth > 0; }).length;
  document.body.setAttribute("data-images-total", String(images.length));
  document.body.setAttribute("data-images-loaded", String(loaded));
});
</script>
</body>
</html>
""")
    with open(path + ".tmp", "w") as f:
        f.write("".join(parts))
    os.replace(path + ".tmp", path)


if __name__ == "__main__":
    main()
