#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Fidelity harness: NDF images of baked assets against the reference evaluator.

For every normal map and asset it draws random footprints (x, y uniform over the map, sigma from a
list or log-uniform in a range; seeded), asks the asset for its NDF image (`glintquery image`),
computes the reference bin-averaged image (`glintref image`, at the asset's resolution R, sigma_r,
rate and ingest options) and reports the relative L1 error over the image,

    rel_L1 = sum_bins |A - Ref| / sum_bins |Ref|,

as a markdown table (per map and sigma: median and 90th percentile per asset) and as JSON (every
footprint). The smooth baseline is the whole map's NDF, one image per map, scored the same way
against every reference image: what a single smooth lobe fitted to the map could at best give.

Whole-map NDF (--baseline):
  splat (default)  ndfgen bakes one footprint of sigma = 0.6 max(width, height) texels (--levels 1,
                   one centre, wrap repeat). On a periodic map a Gaussian footprint of std sigma
                   weights the texels with a relative ripple of 2 exp(-2 pi^2 sigma^2 / P^2)
                   (1.6e-3 at sigma = 0.6 P), and the lobes' position shift and spatial blur vanish
                   at that sigma, so the image is the position-independent NDF of the whole map.
  ref              glintref at sigma = max(width, height) (exact, but 36 W*H lobes: hours on 1024^2).
  mean             the mean of the reference images of each sigma (cheap but biased: it contains
                   the image it is compared against).
  none             no baseline.

References: `glintref image` (exact bin averages, lobes truncated at 6 sigma) for sigma up to
--splat-above (default 16 texels). Its cost grows as sigma^2 (about 170 s of one core for one
128^2 image at sigma 64), so above that the reference is one footprint splatted by ndfgen
(--levels 1, --no-flakes) on a copy of the map shifted periodically by whole texels so that the
footprint lands on a centre of that level: footprint centres of those sigmas keep the fractional
part of the map's centre (whole texels for even sizes). ndfgen keeps one centre along a repeating
axis only where the footprint is flat over it, and reweighs the footprints of centres closer than
2.5 stds into a partition of unity; so an axis the footprint is not flat over is repeated over 2
or 6 periods (two centres 1 or 3 periods apart, the first at the shifted footprint), and the
image is that of the plain Gaussian footprint. The splatter truncates these footprints at 4 sigma
(--footprint-truncation 4; the bakes' default is 3.5) and agrees with glintref to relative L1 2e-4
to 5e-4 (sigma 12 to 60, maps of 64 x 48 to 1024^2, odd and even sizes, axes of 1, 2 and 6
periods); it is the baker's own evaluator, so
`--splat-above -1` gives an independent reference everywhere when time allows. The shift needs a
non-interlaced 8/16-bit PNG and wrap repeat; other maps use glintref at every sigma.

Caching (--cache, default build/fidelity-cache under the repository): reference images are keyed by
(map content hash, x, y, sigma, R, sigma_r, and any non-default ingest option); baked assets by
(map hash, tool binary hash, tool arguments); the assets' images by (asset file, size, mtime, the
glintquery binary's hash, x, y, sigma); so a rerun only computes what is new, and a rebuilt tool
whose binary is unchanged reuses every result. Footprints are
drawn from Random((seed, map hash, sigma)), so the same seed gives the same footprints on every run
and for every asset, and a new asset reuses all references.

Targets (--targets MEDIAN:P90:RATIO, default 0.12:0.25:0.35, the quality targets of the NDF
paths): every cell (map, sigma, asset) must have a median error <= MEDIAN, a 90th percentile
<= P90, and a median <= RATIO times the median of the baseline of its own reference parameters
(one per NDF resolution when the assets differ in it). Where the baseline's median is below
--floor (default 1e-4) the footprint sees the whole map's NDF and both images are equal up to float
rounding: the ratio is not taken there, and the cell meets it if the asset's median is below the
floor too. The markdown ends with the worst cell of each test per asset and every cell that misses;
the JSON carries the same under "targets"; --check exits 1 when a cell misses (or an asset
has no measurement on a map, when its bake failed).

Usage:
  # bake the current defaults and score them (the "before" run of bench/fidelity-survey.md)
  python3 scripts/fidelity.py /path/maps/*.png \\
      --bake pyramid=ndfgen --bake rank16="tensorpack --rank 16" --bake rank32="tensorpack --rank 32" \\
      --sigmas 0.5 1 2 4 8 16 32 64 --footprints 6 --splat-above 8 --jobs 2 \\
      --band 0.5:4 --band 8:64 --markdown before.md --json before.json

  # the survey: configurations against log-uniform sigma from 8 to the map size
  python3 scripts/fidelity.py maps/a.png maps/b.png --bake d=ndfgen \\
      --bake s12full="ndfgen --stride 12 --converge-mse 1e-9" --sigma-range 8 1024 --clip-range \\
      --sigma-count 16 --footprints 1 --seed 13 --splat-above 8 --band 8:16 --band 16:64 --band 64:inf

  # existing assets ({stem} = the map's file name without extension), log-uniform sigma
  python3 scripts/fidelity.py maps/a.png maps/b.exr --asset mine=assets/{stem}.gbk \\
      --sigma-range 8 512 --footprints 24

  # fewer footprints where the reference is expensive (its cost grows as sigma^2)
  python3 scripts/fidelity.py m.png --bake p=ndfgen --footprints 6 --footprints-for 64:3

Options worth knowing: --bin DIR (tools; default build/bin), --jobs N (parallel tool processes; each
runs with -j1, bakes run one at a time with all cores so their timings mean something), --seed,
--baseline, --sigma-r / --res (only when an asset does not say), --ingest "ARGS" (extra ingest
options passed to every tool, e.g. "--flip-green"). Requires only python3 (no numpy): the tools'
EXR output (zip, scanline, float or half) is decoded here.
"""

import argparse
import concurrent.futures
import hashlib
import json
import math
import os
import random
import resource
import shlex
import statistics
import struct
import subprocess
import sys
import tempfile
import threading
import time
import zlib

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# The splat references and baselines cut footprints at 4 std, closer to the exact images than the
# bakes' default of 3.5 (and what every cached "_splat3" reference was made with).
REFERENCE_TRUNCATION = ["--footprint-truncation", "4"]


# ----------------------------------------------------------------------------------------------
# EXR reading (scanline, one or more channels; none / zips / zip compression; half or float)

def _read_exr(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"\x76\x2f\x31\x01":
        raise ValueError(path + ": not an OpenEXR file")
    if data[5] & 0x02:
        raise ValueError(path + ": tiled EXR is not supported")
    pos = 8
    header = {}
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        end2 = data.index(b"\0", end + 1)
        type_name = data[end + 1:end2].decode()
        (size,) = struct.unpack_from("<i", data, end2 + 1)
        value = data[end2 + 5:end2 + 5 + size]
        header[name] = (type_name, value)
        pos = end2 + 5 + size
    pos += 1
    channels = []
    chl = header["channels"][1]
    p = 0
    while chl[p] != 0:
        end = chl.index(b"\0", p)
        name = chl[p:end].decode()
        (ptype,) = struct.unpack_from("<i", chl, end + 1)
        channels.append((name, ptype))
        p = end + 1 + 16
    channels.sort()
    compression = header["compression"][1][0]
    x0, y0, x1, y1 = struct.unpack("<iiii", header["dataWindow"][1])
    width, height = x1 - x0 + 1, y1 - y0 + 1
    lines_per_block = {0: 1, 2: 1, 3: 16}.get(compression)
    if lines_per_block is None:
        raise ValueError(path + ": EXR compression %d is not supported" % compression)
    blocks = (height + lines_per_block - 1) // lines_per_block
    offsets = struct.unpack_from("<%dQ" % blocks, data, pos)
    out = [0.0] * (width * height)
    for off in offsets:
        y, size = struct.unpack_from("<ii", data, off)
        raw = data[off + 8:off + 8 + size]
        lines = min(lines_per_block, y1 + 1 - y)
        expected = sum(width * (2 if t == 1 else 4) for _, t in channels) * lines
        if compression != 0 and size < expected:
            t = bytearray(zlib.decompress(raw))
            for i in range(1, len(t)):
                t[i] = (t[i - 1] + t[i] - 128) & 0xFF
            half = (len(t) + 1) // 2
            u = bytearray(len(t))
            u[0::2] = t[:half]
            u[1::2] = t[half:]
            raw = bytes(u)
        p = 0
        for line in range(lines):
            row = y - y0 + line
            for ci, (_, ptype) in enumerate(channels):
                if ptype == 1:
                    vals = struct.unpack_from("<%de" % width, raw, p)
                    p += 2 * width
                elif ptype == 2:
                    vals = struct.unpack_from("<%df" % width, raw, p)
                    p += 4 * width
                else:
                    raise ValueError(path + ": uint EXR channels are not supported")
                if ci == 0:
                    out[row * width:(row + 1) * width] = vals
    return width, height, out


# ----------------------------------------------------------------------------------------------
# PNG reading and writing (non-interlaced, 8/16-bit grey/RGB/RGBA), for periodic shifts of a map

def _read_png_rows(path):
    """(width, height, bytes per pixel, header chunk, list of unfiltered rows) or None if unsupported."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        return None
    pos, idat, ihdr = 8, [], None
    while pos < len(data):
        (length,) = struct.unpack_from(">I", data, pos)
        ctype = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        if ctype == b"IHDR":
            ihdr = body
        elif ctype == b"IDAT":
            idat.append(body)
        pos += 12 + length
    width, height, depth, color, _, _, interlace = struct.unpack(">IIBBBBB", ihdr)
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(color)
    if channels is None or interlace or depth not in (8, 16):
        return None
    bpp = channels * depth // 8
    raw = zlib.decompress(b"".join(idat))
    stride = width * bpp
    rows, prev = [], bytearray(stride)
    for r in range(height):
        ftype = raw[r * (stride + 1)]
        line = bytearray(raw[r * (stride + 1) + 1:(r + 1) * (stride + 1)])
        if ftype == 1:
            for i in range(bpp, stride):
                line[i] = (line[i] + line[i - bpp]) & 0xFF
        elif ftype == 2:
            line = bytearray((a + b) & 0xFF for a, b in zip(line, prev))
        elif ftype == 3:
            for i in range(stride):
                left = line[i - bpp] if i >= bpp else 0
                line[i] = (line[i] + ((left + prev[i]) >> 1)) & 0xFF
        elif ftype == 4:
            for i in range(stride):
                a = line[i - bpp] if i >= bpp else 0
                b = prev[i]
                c = prev[i - bpp] if i >= bpp else 0
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else (b if pb <= pc else c))) & 0xFF
        rows.append(bytes(line))
        prev = line
    return width, height, bpp, ihdr, rows


def _write_png_shifted(path, png, dx, dy, tiles=(1, 1)):
    """Writes the map periodically shifted by (dx, dy) whole texels (texel (c, r) moves to (c+dx, r+dy)),
    repeated tiles[0] times across and tiles[1] times down: the same periodic surface."""
    width, height, bpp, ihdr, rows = png
    dx %= width
    dy %= height
    cut = (width - dx) * bpp
    shifted = [rows[(r - dy) % height] for r in range(height)]
    body = b"".join(b"\x00" + (row[cut:] + row[:cut]) * tiles[0] for row in shifted) * tiles[1]
    header = struct.pack(">II", width * tiles[0], height * tiles[1]) + ihdr[8:]

    def chunk(ctype, payload):
        return struct.pack(">I", len(payload)) + ctype + payload + struct.pack(">I", zlib.crc32(ctype + payload))

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(body, 1)) +
                chunk(b"IEND", b""))


# ----------------------------------------------------------------------------------------------
# helpers

def _sha_file(path, n=16):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()[:n]


def _run(cmd, log_err=True):
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if proc.returncode != 0:
        raise RuntimeError("command failed (exit %d): %s\n%s" % (proc.returncode, " ".join(map(shlex.quote, cmd)),
                                                                 proc.stderr.strip()[-2000:]))
    return proc.stdout


def _rel_l1(a, ref):
    den = sum(abs(r) for r in ref)
    num = sum(abs(x - r) for x, r in zip(a, ref))
    return num / den if den > 0 else float("nan")


def _percentile(values, q):
    """Linear interpolation between closest ranks (numpy's default)."""
    v = sorted(values)
    if not v:
        return float("nan")
    k = (len(v) - 1) * q / 100.0
    lo, hi = int(math.floor(k)), int(math.ceil(k))
    return v[lo] + (v[hi] - v[lo]) * (k - lo)


def _fmt_num(x):
    return ("%.6f" % x).rstrip("0").rstrip(".")


# ----------------------------------------------------------------------------------------------

class Harness:
    def __init__(self, args):
        self.args = args
        self.bin = os.path.abspath(args.bin)
        self.cache = os.path.abspath(args.cache)
        for sub in ("ref", "assets", "baseline", "query", "tmp"):
            os.makedirs(os.path.join(self.cache, sub), exist_ok=True)
        self.ingest = shlex.split(args.ingest) if args.ingest else []
        self._tool_hash = {}
        self._png = {}
        self._png_lock = threading.Lock()

    def tool(self, name):
        return os.path.join(self.bin, name)

    def tool_hash(self, name):
        if name not in self._tool_hash:
            self._tool_hash[name] = _sha_file(self.tool(name), 12)
        return self._tool_hash[name]

    # -- maps
    def map_info(self, path):
        """Width, height and content hash of a normal map (through glintref's ingest report)."""
        digest = _sha_file(path)
        meta = os.path.join(self.cache, "ref", digest + ".map.json")
        if os.path.exists(meta):
            with open(meta) as f:
                return json.load(f)
        tmp = os.path.join(self.cache, "tmp", "probe-%s-%d.exr" % (digest, os.getpid()))
        out = _run([self.tool("glintref"), "--json", "-q", "-j1", "image", path, "--at", "0.5,0.5", "--sigma", "0.5",
                    "--res", "2", "-o", tmp] + self.ingest)
        os.remove(tmp)
        doc = json.loads(out)
        info = {"hash": digest, "name": os.path.basename(path), "width": doc["map"]["width"],
                "height": doc["map"]["height"], "wrap": doc["map"]["wrap"]}
        try:
            info["png_ok"] = self.png(path) is not None
        except Exception:  # not a PNG the shifter understands: references from glintref only
            info["png_ok"] = False
        with open(meta, "w") as f:
            json.dump(info, f)
        return info

    # -- assets
    def bake(self, map_path, minfo, label, spec):
        words = shlex.split(spec)
        tool, targs = words[0], words[1:]
        key = hashlib.sha256(json.dumps([minfo["hash"], tool, self.tool_hash(tool), targs, self.ingest]).encode())
        stem = "%s-%s-%s" % (os.path.splitext(minfo["name"])[0], label, key.hexdigest()[:12])
        asset = os.path.join(self.cache, "assets", stem + ".gbk")
        meta = asset + ".json"
        if os.path.exists(asset) and os.path.exists(meta):
            with open(meta) as f:
                return asset, json.load(f)
        cmd = [self.tool(tool), "--json", "-q"] + targs + self.ingest + [map_path, "-o", asset]
        sys.stderr.write("bake %s %s: %s\n" % (minfo["name"], label, " ".join(shlex.quote(w) for w in cmd[1:])))
        t0 = time.time()
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        try:
            out = _run(cmd)
        except RuntimeError as e:
            sys.stderr.write("bake %s %s FAILED: %s\n" % (minfo["name"], label, e))
            return None, {"label": label, "command": " ".join([tool] + targs), "failed": str(e).splitlines()[-1]}
        seconds = time.time() - t0
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
        doc = json.loads(out)
        record = {"label": label, "command": " ".join([tool] + targs), "seconds": seconds, "cpu_seconds": cpu,
                  "bytes": os.path.getsize(asset), "tool_json": doc}
        with open(meta, "w") as f:
            json.dump(record, f)
        return asset, record

    def asset_params(self, asset):
        doc = json.loads(_run([self.tool("glintinfo"), "--json", "-q", "info", asset]))
        md = doc.get("metadata", {})
        p = dict(md.get("parameters", {}))
        if isinstance(p.get("pyramid"), dict):  # tensorpack nests the pyramid's parameters
            p = dict(p["pyramid"], **{k: v for k, v in p.items() if k != "pyramid"})
        a = md.get("asset", {})
        res = a.get("ndf_res", p.get("ndf_res", self.args.res))
        sigma_r = a.get("sigma_r", p.get("sigma_r", self.args.sigma_r))
        levels = a.get("levels") or md.get("levels") or []
        sigmas = [l.get("sigma") for l in levels if isinstance(l, dict) and "sigma" in l]
        # The asset's ingest options, so that the reference reads the map the same way.
        ing = p.get("ingest", {})
        ingest = []
        if ing.get("encoding", "auto") != "auto":
            ingest += ["--encoding", str(ing["encoding"])]
        if ing.get("flip_green"):
            ingest.append("--flip-green")
        if ing.get("height"):
            ingest += ["--height", "--height-scale", repr(float(ing.get("height_scale", 1.0)))]
        if ing.get("wrap", "repeat") != "repeat":
            ingest += ["--wrap", str(ing["wrap"])]
        if ing.get("part", 0):
            ingest += ["--part", str(ing["part"])]
        if ing.get("fix_nonfinite"):
            ingest.append("--fix-nonfinite")
        return {"res": int(res), "sigma_r": float(sigma_r), "rate": int(p.get("rate", 1)), "kind": doc.get("asset_kind"),
                "ingest": ingest, "level_sigmas": sigmas, "bytes": doc.get("file_size", os.path.getsize(asset))}

    # -- footprints
    def footprints(self, minfo, sigma):
        n = self.args.footprints
        for s, k in self.args.footprints_for:
            if abs(s - sigma) < 1e-9:
                n = k
        rng = random.Random("%d:%s:%s" % (self.args.seed, minfo["hash"], repr(float(sigma))))
        fps = [(round(rng.uniform(0, minfo["width"]), 3), round(rng.uniform(0, minfo["height"]), 3)) for _ in range(n)]
        if self.splat_sigma(minfo, sigma):
            # A whole-texel shift of the map must bring the footprint onto the one-centre grid's
            # centre (W/2, H/2): keep the fractional part of that centre.
            fx, fy = (minfo["width"] / 2) % 1.0, (minfo["height"] / 2) % 1.0
            fps = [(math.floor(x) + fx, math.floor(y) + fy) for x, y in fps]
        return fps

    def splat_sigma(self, minfo, sigma):
        """Whether this sigma's references come from the shifted one-footprint splat (see --splat-above)."""
        return (self.args.splat_above is not None and sigma > self.args.splat_above and minfo.get("png_ok", False)
                and minfo["wrap"] == "repeat" and "--wrap" not in self.ingest)

    def png(self, map_path):
        with self._png_lock:
            if map_path not in self._png:
                self._png[map_path] = _read_png_rows(map_path)
            return self._png[map_path]

    def sigma_list(self, minfo):
        if self.args.sigma_range:
            lo, hi = self.args.sigma_range
            hi = min(hi, float(max(minfo["width"], minfo["height"]))) if self.args.clip_range else hi
            rng = random.Random("%d:%s:sigmas" % (self.args.seed, minfo["hash"]))
            return sorted(round(math.exp(rng.uniform(math.log(lo), math.log(hi))), 3)
                          for _ in range(self.args.sigma_count))
        size = float(max(minfo["width"], minfo["height"]))
        return [float(s) for s in self.args.sigmas if not self.args.clip_range or s <= size]

    # -- images
    def ref_args(self, params):
        extra = list(params.get("ingest") or self.ingest)
        if params["rate"] != 1:
            extra += ["--rate", str(params["rate"])]
        return extra

    def reference(self, map_path, minfo, x, y, sigma, params):
        extra = self.ref_args(params)
        tag = "" if not extra else "_" + hashlib.sha256(" ".join(extra).encode()).hexdigest()[:8]
        splat = self.splat_sigma(minfo, sigma) and "--wrap" not in extra
        if splat:
            # "_splat" references were answered by the clustered lobes, "_splat2" ones (made after ndfgen
            # kept two centres on repeating axes) partly by a neighbouring centre: neither is reused.
            tag += "_splat3"
        name = "%s_%s_%s_%s_%d_%s%s.exr" % (minfo["hash"], _fmt_num(x), _fmt_num(y), _fmt_num(sigma), params["res"],
                                            _fmt_num(params["sigma_r"]), tag)
        path = os.path.join(self.cache, "ref", name)
        if not os.path.exists(path) and splat:
            self.splat_reference(map_path, minfo, x, y, sigma, params, extra, path)
        if not os.path.exists(path):
            tmp = path + ".%d.tmp.exr" % os.getpid()
            _run([self.tool("glintref"), "-q", "-j1", "image", map_path, "--at", "%r,%r" % (x, y), "--sigma", repr(sigma),
                  "--res", str(params["res"]), "--sigma-r", repr(params["sigma_r"]), "-o", tmp] + extra)
            os.replace(tmp, path)
        return _read_exr(path)[2]

    def splat_reference(self, map_path, minfo, x, y, sigma, params, extra, path):
        """One footprint baked by ndfgen on a periodically shifted copy of the map (see --splat-above)."""
        width, height = minfo["width"], minfo["height"]
        cx, cy = width / 2, height / 2
        dx, dy = int(round(cx - x)), int(round(cy - y))
        base = path + ".%d.%d" % (os.getpid(), threading.get_ident())
        try:
            # ndfgen keeps one centre along a repeating axis only where the footprint is flat over it
            # (sigma >= 0.62 periods; pyramid_builder.h, levelGeometry), and otherwise two, whose
            # footprints it reweighs into a partition of unity when they lie within 2.5 footprint
            # stds (splat.h, footprintPartition), which is not the Gaussian footprint measured here.
            # So such an axis is repeated over 2 m periods (m = 1, or 3 where a period is within 2.5
            # stds): two centres m periods apart, the first at m / 2 periods, which is the map's
            # centre shifted by whole periods, where the shift put the footprint.
            def periods(size):
                if sigma >= 0.62 * size:
                    return 1
                return 2 if size > 2.5 * (sigma + 0.5) else 6
            tiles = (periods(width), periods(height))
            _write_png_shifted(base + ".png", self.png(map_path), dx, dy, tiles)
            # --no-flakes: the pyramid alone answers (with flakes and lobes the asset's own hand-over
            # would answer this footprint from the clustered lobes).
            longest = max(width * tiles[0], height * tiles[1])
            report = json.loads(_run([self.tool("ndfgen"), "--json", "-q", "-j1", "--levels", "1",
                                      "--stride", str(2 * longest), "--max-size", str(max(16384, longest)),
                                      "--sigma0", repr(sigma), "--ndf-res", str(params["res"]),
                                      "--sigma-r", repr(params["sigma_r"]), "--no-flakes", base + ".png",
                                      "-o", base + ".gbk"] + REFERENCE_TRUNCATION + extra))
            level = report["levels"][0]
            at = level["first_centre"]
            for axis, (c, size) in enumerate(((cx, width), (cy, height))):
                expect = c + (tiles[axis] // 2 - 1) / 2 * size if tiles[axis] > 1 else c
                if level["grid"][axis] != min(tiles[axis], 2) or abs(at[axis] - expect) > 1e-9:
                    raise RuntimeError("splat reference of %s at sigma %r: centres %r from %r, expected one at %r" %
                                       (map_path, sigma, level["grid"], at, (cx, cy)))
            _run([self.tool("glintquery"), "-q", "-j1", "image", base + ".gbk", "--at", "%r,%r" % tuple(at),
                  "--sigma", repr(sigma), "-o", base + ".exr"])
            os.replace(base + ".exr", path)
        finally:
            for ext in (".png", ".gbk", ".exr"):
                if os.path.exists(base + ext):
                    os.remove(base + ext)

    def query(self, asset, x, y, sigma):
        # Cached by the asset's name, size and modification time and the glintquery binary.
        st = os.stat(asset)
        key = hashlib.sha256(json.dumps([os.path.abspath(asset), st.st_size, st.st_mtime_ns,
                                         self.tool_hash("glintquery"), x, y, sigma]).encode()).hexdigest()[:24]
        path = os.path.join(self.cache, "query", key + ".exr")
        if not os.path.exists(path):
            tmp = path + ".%d.%d.tmp.exr" % (os.getpid(), threading.get_ident())
            _run([self.tool("glintquery"), "-q", "-j1", "image", asset, "--at", "%r,%r" % (x, y), "--sigma", repr(sigma),
                  "-o", tmp])
            os.replace(tmp, path)
        return _read_exr(path)[2]

    def baseline(self, map_path, minfo, params, mean_of=None):
        mode = self.args.baseline
        if mode == "mean":
            n = len(mean_of)
            return [sum(img[i] for img in mean_of) / n for i in range(len(mean_of[0]))]
        size = max(minfo["width"], minfo["height"])
        extra = self.ref_args(params)
        # "pyramid-only": the splat baseline bakes without flakes, so its image is the splat's and not
        # the clustered lobes' (older cache entries lack the tag).
        key = hashlib.sha256(json.dumps([minfo["hash"], mode, params["res"], params["sigma_r"], extra,
                                         "pyramid-only"]).encode())
        path = os.path.join(self.cache, "baseline", "%s_%s.exr" % (minfo["hash"], key.hexdigest()[:12]))
        if not os.path.exists(path):
            tmp = path + ".%d.tmp.exr" % os.getpid()
            if "--wrap" in extra:  # the whole-map NDF weights every texel once: always periodic
                i = extra.index("--wrap")
                extra = extra[:i] + extra[i + 2:]
            wrap = ["--wrap", "repeat"]
            if mode == "ref":
                _run([self.tool("glintref"), "-q", "image", map_path, "--at", "%r,%r" % (size / 2, size / 2),
                      "--sigma", str(size), "--res", str(params["res"]), "--sigma-r", repr(params["sigma_r"]),
                      "-o", tmp] + extra + wrap)
            else:
                gbk = path + ".gbk"
                _run([self.tool("ndfgen"), "-q", "--levels", "1", "--stride", str(2 * size), "--sigma0", repr(0.6 * size),
                      "--ndf-res", str(params["res"]), "--sigma-r", repr(params["sigma_r"]), "--no-flakes", map_path,
                      "-o", gbk] + REFERENCE_TRUNCATION + extra + wrap)
                _run([self.tool("glintquery"), "-q", "image", gbk, "--at", "%r,%r" % (minfo["width"] / 2,
                      minfo["height"] / 2), "--sigma", repr(0.6 * size), "-o", tmp])
                os.remove(gbk)
            os.replace(tmp, path)
        return _read_exr(path)[2]


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__.split("\n", 2)[2])
    ap.add_argument("maps", nargs="+", help="normal maps (any format the tools read)")
    ap.add_argument("--asset", action="append", default=[], metavar="LABEL=PATH",
                    help="an existing asset per map; {stem} and {name} expand to the map's file stem / name")
    ap.add_argument("--bake", action="append", default=[], metavar="LABEL=\"TOOL ARGS\"",
                    help="bake an asset per map with ndfgen or tensorpack and these arguments (cached)")
    ap.add_argument("--sigmas", nargs="+", type=float, default=[0.5, 1, 2, 4, 8, 16, 32, 64],
                    help="footprint sigmas in texels (default 0.5 1 2 4 8 16 32 64)")
    ap.add_argument("--sigma-range", nargs=2, type=float, metavar=("LO", "HI"),
                    help="instead of --sigmas: --sigma-count sigmas log-uniform in [LO, HI] (per map, seeded)")
    ap.add_argument("--sigma-count", type=int, default=8)
    ap.add_argument("--clip-range", action="store_true", help="no sigma above the map size (--sigmas and --sigma-range)")
    ap.add_argument("--band", action="append", default=[], metavar="LO:HI",
                    type=lambda s: (float(s.split(":")[0]), float(s.split(":")[1])),
                    help="summary rows over all footprints with LO <= sigma <= HI (repeatable; HI may be inf)")
    ap.add_argument("--footprints", type=int, default=6, help="footprints per map and sigma (default 6)")
    ap.add_argument("--footprints-for", action="append", default=[], metavar="SIGMA:N",
                    type=lambda s: (float(s.split(":")[0]), int(s.split(":")[1])),
                    help="a different number of footprints at one sigma (repeatable)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--baseline", choices=["splat", "ref", "mean", "none"], default="splat")
    ap.add_argument("--splat-above", type=float, default=16.0,
                    help="references of larger sigmas from the shifted one-footprint splat (default 16; -1 = never)")
    ap.add_argument("--res", type=int, default=128, help="NDF resolution when an asset does not record it")
    ap.add_argument("--sigma-r", type=float, default=0.005, help="sigma_r when an asset does not record it")
    ap.add_argument("--ingest", default="", help="extra ingest options for every tool, e.g. \"--flip-green\"")
    ap.add_argument("--bin", default=os.path.join(REPO, "build", "bin"))
    ap.add_argument("--cache", default=os.path.join(REPO, "build", "fidelity-cache"))
    ap.add_argument("--jobs", type=int, default=2, help="tool processes at a time (default 2)")
    ap.add_argument("--targets", default="0.12:0.25:0.35", metavar="MEDIAN:P90:RATIO",
                    help="quality targets per cell (default 0.12:0.25:0.35; see the module help)")
    ap.add_argument("--floor", type=float, default=1e-4,
                    help="baseline median below which the ratio target is not taken (default 1e-4)")
    ap.add_argument("--check", action="store_true", help="exit 1 when a cell misses a target")
    ap.add_argument("--markdown", help="write the markdown tables here (always printed)")
    ap.add_argument("--json", dest="json_out", help="write every measurement as JSON here")
    args = ap.parse_args(argv)
    if args.splat_above is not None and args.splat_above < 0:
        args.splat_above = None
    try:
        args.targets = tuple(float(v) for v in args.targets.split(":"))
    except ValueError:
        args.targets = ()
    if len(args.targets) != 3 or not all(v > 0 for v in args.targets):
        ap.error("--targets must be MEDIAN:P90:RATIO, three numbers > 0")
    if not args.asset and not args.bake and args.baseline == "none":
        ap.error("nothing to measure: give --asset, --bake or a baseline")
    return args


def main(argv):
    args = parse_args(argv)
    h = Harness(args)
    specs = []
    for a in args.asset:
        label, _, pattern = a.partition("=")
        specs.append(("asset", label, pattern))
    for b in args.bake:
        label, _, spec = b.partition("=")
        specs.append(("bake", label, spec))
    labels = [s[1] for s in specs]

    results = {"seed": args.seed, "baseline": args.baseline, "maps": []}
    pool = concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs))
    t_start = time.time()
    for map_path in args.maps:
        minfo = h.map_info(map_path)
        assets = []
        bakes = {}
        for kind, label, spec in specs:  # bakes run one at a time, nothing else running
            if kind == "asset":
                stem = os.path.splitext(minfo["name"])[0]
                path = spec.replace("{stem}", stem).replace("{name}", minfo["name"])
                record = {"label": label, "command": "(given) " + os.path.basename(path), "seconds": None}
            else:
                path, record = h.bake(map_path, minfo, label, spec)
                if path is None:
                    bakes[label] = record
                    continue
            params = h.asset_params(path)
            record["bytes"] = params["bytes"]
            record["level_sigmas"] = params["level_sigmas"]
            tj = record.get("tool_json") or {}
            if not record["level_sigmas"] and tj.get("levels"):  # tensor-ndf: sigma0 * 2^level
                tp = tj.get("parameters") or {}
                sigma0 = float(tp.get("sigma0", (tp.get("pyramid") or {}).get("sigma0", 8.0)))
                record["level_sigmas"] = [sigma0 * 2 ** l.get("level", i) for i, l in enumerate(tj["levels"])]
            bakes[label] = record
            assets.append((label, path, params))
        entry = {"map": minfo, "bakes": bakes, "sigmas": []}
        for sigma in h.sigma_list(minfo):
            fps = h.footprints(minfo, sigma)
            # distinct reference parameter sets among the assets (R, sigma_r, rate)
            pkeys = {}
            for label, path, params in assets:
                pkeys.setdefault(baseline_key(params), params)
            if not pkeys:
                params = {"res": args.res, "sigma_r": args.sigma_r, "rate": 1, "ingest": []}
                pkeys[baseline_key(params)] = params
            refs = {}
            futs = {}
            for pk, params in pkeys.items():
                for i, (x, y) in enumerate(fps):
                    futs[(pk, i)] = pool.submit(h.reference, map_path, minfo, x, y, sigma, params)
            qfuts = {}
            for label, path, params in assets:
                for i, (x, y) in enumerate(fps):
                    qfuts[(label, i)] = pool.submit(h.query, path, x, y, sigma)
            for k, f in futs.items():
                refs[k] = f.result()
            row = {"sigma": sigma, "footprints": [{"x": x, "y": y} for x, y in fps], "errors": {}}
            for label, path, params in assets:
                pk = baseline_key(params)
                row["errors"][label] = [_rel_l1(qfuts[(label, i)].result(), refs[(pk, i)]) for i in range(len(fps))]
            if args.baseline != "none":
                names = {}
                for pk, params in pkeys.items():
                    base = h.baseline(map_path, minfo, params, mean_of=[refs[(pk, i)] for i in range(len(fps))])
                    names[pk] = "baseline" if len(pkeys) == 1 else "baseline R%d" % pk[0]
                    row["errors"][names[pk]] = [_rel_l1(base, refs[(pk, i)]) for i in range(len(fps))]
                # Each asset's ratio target is taken against the baseline of its own reference parameters.
                row["baseline_of"] = {label: names[baseline_key(params)] for label, path, params in assets}
            entry["sigmas"].append(row)
            sys.stderr.write("%s sigma %g: %s (%.0f s)\n" % (minfo["name"], sigma, "  ".join(
                "%s %.3f" % (k, statistics.median(v)) for k, v in row["errors"].items()), time.time() - t_start))
        results["maps"].append(entry)
    pool.shutdown()

    results["bands"] = args.band
    results["targets"] = check_targets(results, labels, args.targets, args.floor)
    md = render_markdown(results, labels)
    print(md)
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write(md)
    if args.json_out:
        with open(args.json_out, "w") as f:
            json.dump(results, f, indent=1)
    return 1 if args.check and any(t["misses"] for t in results["targets"]["assets"].values()) else 0


def baseline_key(params):
    """The reference parameters an asset is scored with (NDF resolution, sigma_r, rate, ingest): assets
    that share them share references and a baseline."""
    return (params["res"], params["sigma_r"], params["rate"], tuple(params["ingest"]))


def check_targets(results, labels, targets, floor):
    """Each asset's worst cell for each target, and the cells that miss one (see the module help)."""
    median_max, p90_max, ratio_max = targets
    summary = {"median": median_max, "p90": p90_max, "ratio": ratio_max, "floor": floor, "assets": {}}
    for label in labels:
        worst = {"median": None, "p90": None, "ratio": None}
        misses = []
        for entry in results["maps"]:
            if not any(row["errors"].get(label) for row in entry["sigmas"]):  # its bake failed
                misses.append({"map": entry["map"]["name"], "sigma": None, "missed": ["not measured"]})
            for row in entry["sigmas"]:
                errors = row["errors"].get(label)
                if not errors:
                    continue
                where = {"map": entry["map"]["name"], "sigma": row["sigma"]}
                median, p90 = statistics.median(errors), _percentile(errors, 90)
                base = row["errors"].get(row.get("baseline_of", {}).get(label, "baseline"))
                base_median = statistics.median(base) if base else None
                ratio = median / base_median if base_median is not None and base_median >= floor else None
                for name, value in (("median", median), ("p90", p90), ("ratio", ratio)):
                    if value is not None and (worst[name] is None or value > worst[name]["value"]):
                        worst[name] = dict(where, value=value)
                missed = [name for name, value, bound in (("median", median, median_max), ("p90", p90, p90_max),
                                                          ("ratio", ratio, ratio_max))
                          if value is not None and not value <= bound]
                if base_median is not None and base_median < floor and not median < floor:
                    missed.append("floor")
                if missed:
                    misses.append(dict(where, missed=missed, median=median, p90=p90, baseline=base_median))
        summary["assets"][label] = {"worst": worst, "misses": misses}
    return summary


def render_markdown(results, labels):
    out = []
    cols = None
    out.append("Relative L1 of the NDF image against the reference, median / 90th percentile over the footprints "
               "(baseline: the whole map's NDF, %s).\n" % results["baseline"])
    for entry in results["maps"]:
        m = entry["map"]
        names = list(entry["sigmas"][0]["errors"].keys()) if entry["sigmas"] else labels
        if cols != names:
            cols = names
        out.append("\n**%s** (%dx%d)\n" % (m["name"], m["width"], m["height"]))
        out.append("| sigma (texels) | n | " + " | ".join(names) + " |")
        out.append("|---|---|" + "---|" * len(names))
        for row in entry["sigmas"]:
            cells = []
            for n in names:
                v = row["errors"].get(n, [])
                cells.append("%.3f / %.3f" % (statistics.median(v), _percentile(v, 90)) if v else "-")
            out.append("| %s | %d | %s |" % (_fmt_num(row["sigma"]), len(row["footprints"]), " | ".join(cells)))
        for lo, hi in results.get("bands", []):
            rows = [r for r in entry["sigmas"] if lo <= r["sigma"] <= hi]
            cells = []
            for n in names:
                v = [e for r in rows for e in r["errors"].get(n, [])]
                cells.append("**%.3f / %.3f**" % (statistics.median(v), _percentile(v, 90)) if v else "-")
            count = sum(len(r["footprints"]) for r in rows)
            out.append("| **%s to %s** | %d | %s |" % (_fmt_num(lo), _fmt_num(hi), count, " | ".join(cells)))
    t = results.get("targets")
    if t and t["assets"]:
        bounds = (_fmt_num(t["median"]), _fmt_num(t["p90"]), _fmt_num(t["ratio"]), t["floor"])
        out.append("\nTargets: median <= %s, 90th percentile <= %s, median <= %s x the baseline's (not taken "
                   "where the baseline is below %s). Worst cell of each:\n" % bounds)
        out.append("| asset | median | 90th percentile | ratio to the baseline | cells missing a target |")
        out.append("|---|---|---|---|---|")
        for label, a in t["assets"].items():
            cells = []
            for name in ("median", "p90", "ratio"):
                w = a["worst"][name]
                cells.append("-" if w is None else "%.3f (%s, %s)" % (w["value"], w["map"], _fmt_num(w["sigma"])))
            missed = "; ".join("%s%s: %s" % (m["map"], "" if m["sigma"] is None else " " + _fmt_num(m["sigma"]),
                                              ", ".join(m["missed"])) for m in a["misses"]) or "none"
            out.append("| %s | %s | %s |" % (label, " | ".join(cells), missed))
    out.append("\nBakes:\n")
    out.append("| map | asset | command | bake wall (s) | bake CPU (s) | size (MB) | level sigmas |")
    out.append("|---|---|---|---|---|---|---|")
    for entry in results["maps"]:
        for label, b in entry["bakes"].items():
            if b.get("failed"):
                out.append("| %s | %s | `%s` | failed: %s | | | |" % (entry["map"]["name"], label, b["command"],
                                                                      b["failed"][:120]))
                continue
            secs = "-" if b.get("seconds") is None else "%.1f" % b["seconds"]
            cpu = "-" if b.get("cpu_seconds") is None else "%.1f" % b["cpu_seconds"]
            ls = b.get("level_sigmas") or []
            out.append("| %s | %s | `%s` | %s | %s | %.2f | %s |" % (entry["map"]["name"], label, b["command"], secs, cpu,
                                                                    b["bytes"] / 1e6, " ".join(_fmt_num(s) for s in ls)))
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
