#!/usr/bin/env python3
"""Renders the bundled example maps at three distances with the reference P-NDF, the baked assets
(uncompressed ndf-pyramid and tensor-ndf rank 16) and the smooth BRDF, compares every render with
the reference, and writes an HTML report with PNG previews, error heat maps and a table per asset.

    scripts/make-report.py [--bin build/bin] [--maps examples/out/maps] [--out out/report]
                           [--only MAP ...] [--image-size W,H]

Maps missing from --maps are generated with mapgen (the parameters of examples/Makefile). The
report is out/report/index.html; out/report/report.json holds the same figures for scripts.
Scenes: examples/scenes/plane_{near,mid,far}.json (128 x 128 pixels, point + directional light)."""

import argparse
import html
import json
import os
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
# Example maps and the mapgen arguments of examples/Makefile.
MAPS = {
    "scratches": ["scratches", "--size", "256", "--seed", "11"],
    "flakes": ["flakes", "--size", "256", "--seed", "12", "--cone", "12", "--cell", "8"],
    "brushed": ["brushed", "--size", "256", "--seed", "13"],
}
DISTANCES = ["near", "mid", "far"]
MODES = ["reference", "pyramid", "tensor16", "smooth"]
MODE_TITLES = {
    "reference": "reference P-NDF",
    "pyramid": "asset: ndf-pyramid",
    "tensor16": "asset: tensor-ndf rank 16",
    "smooth": "smooth GGX",
}
EXPOSURE = "0.5"


def fail(message):
    sys.stderr.write(f"make-report: error: {message}\n")
    sys.exit(1)


def run(args, capture_json=False):
    """Runs a tool; returns (parsed --json document or None, wall seconds)."""
    start = time.perf_counter()
    proc = subprocess.run([str(a) for a in args], capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if proc.returncode != 0:
        fail(f"{os.path.basename(str(args[0]))} failed ({proc.returncode}): {proc.stderr.strip()}")
    return (json.loads(proc.stdout) if capture_json else None), seconds


def fmt(x, digits=3):
    if x is None:
        return "-"
    if isinstance(x, float):
        if x != 0 and (abs(x) < 1e-3 or abs(x) >= 1e5):
            return f"{x:.{digits - 1}e}"
        return f"{x:.{digits}g}" if abs(x) < 1 else f"{x:.{digits}f}".rstrip("0").rstrip(".")
    return str(x)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bin", default=os.path.join(ROOT, "build", "bin"), help="directory of the tools")
    parser.add_argument("--maps", default=os.path.join(ROOT, "examples", "out", "maps"), help="example maps")
    parser.add_argument("--out", default=os.path.join(ROOT, "out", "report"), help="report directory")
    parser.add_argument("--scenes", default=os.path.join(ROOT, "examples", "scenes"), help="scene files")
    parser.add_argument("--only", action="append", choices=sorted(MAPS), help="render only these maps")
    parser.add_argument("--image-size", help="override the scenes' image size, W,H in pixels")
    opts = parser.parse_args()
    maps = {k: v for k, v in MAPS.items() if not opts.only or k in opts.only}

    tool = lambda name: os.path.join(opts.bin, name)
    for name in ("mapgen", "ndfgen", "tensorpack", "glintref"):
        if not os.access(tool(name), os.X_OK):
            fail(f"{tool(name)} not found: build first (scripts/build.sh) or pass --bin")
    out = opts.out
    work = os.path.join(out, "work")
    img_dir = os.path.join(out, "img")
    os.makedirs(work, exist_ok=True)
    os.makedirs(img_dir, exist_ok=True)
    os.makedirs(opts.maps, exist_ok=True)

    total_start = time.perf_counter()
    report = {"distances": DISTANCES, "modes": MODES, "assets": []}
    for map_name, mapgen_args in maps.items():
        print(f"make-report: {map_name}", file=sys.stderr)
        map_path = os.path.join(opts.maps, f"{map_name}.exr")
        if not os.path.exists(map_path):
            run([tool("mapgen")] + mapgen_args + ["-o", map_path, "--quiet"])
        map_bytes = os.path.getsize(map_path)

        pyramid = os.path.join(work, f"{map_name}_pyramid.gbk")
        _, pyramid_seconds = run([tool("ndfgen"), map_path, "-o", pyramid, "--quiet"])
        tensor = os.path.join(work, f"{map_name}_r16.gbk")
        pack, tensor_seconds = run([tool("tensorpack"), "--rank", "16", map_path, "-o", tensor, "--json"],
                                   capture_json=True)
        entry = {
            "map": map_name,
            "map_bytes": map_bytes,
            "pyramid": {"bake_seconds": pyramid_seconds, "bytes": os.path.getsize(pyramid)},
            "tensor16": {"bake_seconds": tensor_seconds, "bytes": os.path.getsize(tensor),
                         "raw_bytes": pack["raw_bytes"], "ratio": pack["ratio"],
                         "relative_error": pack["relative_error"]},
            "renders": {},
        }
        for distance in DISTANCES:
            scene = os.path.join(opts.scenes, f"plane_{distance}.json")
            renders = {}
            for mode in MODES:
                stem = f"{map_name}_{distance}_{mode}"
                exr = os.path.join(work, stem + ".exr")
                png = os.path.join(img_dir, stem + ".png")
                args = [tool("glintref"), "render", scene, "-o", exr, "--preview", png, "--exposure", EXPOSURE,
                        "--normal-map", map_path, "--json", "--quiet"]
                if opts.image_size:
                    args += ["--image-size", opts.image_size]
                if mode == "pyramid":
                    args += ["--ndf", "asset", "--asset", pyramid]
                elif mode == "tensor16":
                    args += ["--ndf", "asset", "--asset", tensor]
                else:
                    args += ["--ndf", mode]
                doc, _ = run(args, capture_json=True)
                renders[mode] = {"render_seconds": doc["time_seconds"]["render"],
                                 "sigma_mean": doc["footprint_sigma_texels"]["mean"],
                                 "preview": os.path.relpath(png, out), "exr": exr}
            ref_seconds = renders["reference"]["render_seconds"]
            for mode in MODES[1:]:
                stem = f"{map_name}_{distance}_{mode}_error"
                heat = os.path.join(img_dir, stem + ".png")
                doc, _ = run([tool("glintref"), "compare", renders[mode]["exr"], renders["reference"]["exr"],
                              "--heatmap", heat, "--json"], capture_json=True)
                r = renders[mode]
                r.update({"rmse": doc["rmse"], "relative_mse": doc["relative_mse"], "psnr": doc["psnr"],
                          "heatmap": os.path.relpath(heat, out),
                          "speedup": ref_seconds / r["render_seconds"] if r["render_seconds"] > 0 else None})
            for r in renders.values():
                del r["exr"]
            entry["renders"][distance] = renders
        report["assets"].append(entry)
    report["total_seconds"] = time.perf_counter() - total_start

    with open(os.path.join(out, "report.json"), "w") as f:
        json.dump(report, f, indent=2)
    write_html(os.path.join(out, "index.html"), report)
    print(f"make-report: wrote {os.path.join(out, 'index.html')} ({report['total_seconds']:.1f} s)", file=sys.stderr)
    for entry in report["assets"]:
        far = entry["renders"]["far"]["tensor16"]
        print(f"  {entry['map']:10s} tensor r16: {entry['tensor16']['ratio'] * 100:.2f}% of raw, far-view speedup "
              f"{fmt(far['speedup'])}x, relative MSE {fmt(far['relative_mse'])}, PSNR {fmt(far['psnr'])} dB")


def write_html(path, report):
    e = html.escape
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
figure { display: inline-block; margin: 0 0.4em 0.4em 0; text-align: center; }
figure img { width: 160px; height: 160px; image-rendering: pixelated; display: block; }
figcaption { font-size: 0.8em; }
.row { margin-bottom: 0.8em; }
</style>
</head>
<body>
<h1>glintbake report</h1>
<p>Each example map is rendered on a plane at three distances (footprint std in texels given per row)
with the reference P-NDF (exact, from the normal map), the baked assets through the runtime (the
uncompressed ndf-pyramid and the rank-16 tensor-ndf) and a smooth GGX BRDF of the same base
roughness. Errors are against the reference render: relative MSE = sum((x - ref)^2) / sum(ref^2);
heat maps show the per-pixel RMS error, red at 4 x the image's RMSE. Previews are
tone-mapped (exposure """ + EXPOSURE + """, sRGB).</p>
"""]
    for entry in report["assets"]:
        t = entry["tensor16"]
        p = entry["pyramid"]
        parts.append(f"<h2>{e(entry['map'])}</h2>\n")
        parts.append("<table>\n<tr><th class='l'>asset</th><th>bake time (s)</th><th>size (bytes)</th>"
                     "<th>ratio to raw float32 NDF images</th><th>CP relative error</th></tr>\n")
        parts.append(f"<tr><td class='l'>ndf-pyramid (ndfgen)</td><td>{fmt(p['bake_seconds'])}</td>"
                     f"<td>{p['bytes']}</td><td>{fmt(p['bytes'] / t['raw_bytes'])}</td><td>-</td></tr>\n")
        parts.append(f"<tr><td class='l'>tensor-ndf rank 16 (tensorpack)</td><td>{fmt(t['bake_seconds'])}</td>"
                     f"<td>{t['bytes']}</td><td>{fmt(t['ratio'])}</td><td>{fmt(t['relative_error'])}</td></tr>\n")
        parts.append("</table>\n")
        parts.append("<table>\n<tr><th class='l'>distance</th><th>footprint std (texels)</th><th class='l'>mode</th>"
                     "<th>render time (s)</th><th>speedup over reference</th><th>relative MSE</th>"
                     "<th>PSNR (dB)</th></tr>\n")
        for distance in report["distances"]:
            renders = entry["renders"][distance]
            for i, mode in enumerate(report["modes"]):
                r = renders[mode]
                first = f"<td class='l' rowspan='{len(report['modes'])}'>{distance}</td>" \
                        f"<td rowspan='{len(report['modes'])}'>{fmt(renders['reference']['sigma_mean'])}</td>" if i == 0 else ""
                parts.append(f"<tr>{first}<td class='l'>{e(MODE_TITLES[mode])}</td><td>{fmt(r['render_seconds'])}</td>"
                             f"<td>{fmt(r.get('speedup'))}</td><td>{fmt(r.get('relative_mse'))}</td>"
                             f"<td>{fmt(r.get('psnr'))}</td></tr>\n")
        parts.append("</table>\n")
        for distance in report["distances"]:
            renders = entry["renders"][distance]
            parts.append(f"<div class='row'><h3>{e(entry['map'])}, {distance}</h3>\n")
            for mode in report["modes"]:
                r = renders[mode]
                parts.append(f"<figure><img src='{e(r['preview'])}' alt='{e(mode)}'>"
                             f"<figcaption>{e(MODE_TITLES[mode])}</figcaption></figure>\n")
            for mode in report["modes"][1:]:
                r = renders[mode]
                parts.append(f"<figure><img src='{e(r['heatmap'])}' alt='{e(mode)} error'>"
                             f"<figcaption>error: {e(MODE_TITLES[mode])}</figcaption></figure>\n")
            parts.append("</div>\n")
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
