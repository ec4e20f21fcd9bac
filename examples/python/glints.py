#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Bakes a small ndf-pyramid asset from a generated normal map and queries it with numpy.

    PYTHONPATH=build/python python3 examples/python/glints.py [OUT_DIR]
"""
import os
import sys
import tempfile

import numpy as np

import glintbake


def write_pfm(path, size):
    """A scratched-looking normal map as a 3-channel PFM (bottom row first)."""
    rng = np.random.default_rng(5)
    nx = np.zeros((size, size))
    for _ in range(12):  # a few random grooves across the map
        row = rng.integers(0, size)
        nx[row:row + 2, :] += rng.choice([-0.4, 0.4])
    ny = 0.05 * rng.standard_normal((size, size))
    nz = np.sqrt(np.clip(1 - nx ** 2 - ny ** 2, 0.01, 1))
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (size, size))
        f.write(np.stack([nx, ny, nz], -1)[::-1].astype("<f4").tobytes())


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp()
    os.makedirs(out_dir, exist_ok=True)
    map_path, asset_path = os.path.join(out_dir, "grooves.pfm"), os.path.join(out_dir, "grooves.gbk")
    write_pfm(map_path, 64)

    def progress(label, done, total):
        print("\r%-12s %5.1f%%" % (label, 100.0 * done / total), end="", file=sys.stderr)

    summary = glintbake.ndfgen(map_path, output=asset_path, ndf_res=32, stride=8, sigma0=4, progress=progress)
    print(file=sys.stderr)
    print("baked %s: %d levels (%s)" % (asset_path, len(summary["levels"]), summary["stop_reason"]))

    asset = glintbake.open(asset_path)
    print("kind %s, map %s, wrap %s, NDF %d x %d" % (asset.kind, asset.map_size, asset.wrap, asset.resolution,
                                                      asset.resolution))
    # One million s-plane points under one footprint: a single call, no Python loop.
    s = np.random.default_rng(0).uniform(-1, 1, (1_000_000, 2))
    density = asset.eval(np.array([32.0, 32.0, 4.0]), s)
    print("mean density over [-1,1]^2 x 4 = %.3f (the footprint's mass)" % (density.mean() * 4))
    points, pdf = asset.sample(np.array([32.0, 32.0, 4.0]), np.random.default_rng(1).uniform(0, 1, (8, 2)))
    for (sx, sy), p in zip(points, pdf):
        print("  sample s = (%+.3f, %+.3f), pdf %.3f" % (sx, sy, p))


if __name__ == "__main__":
    main()
