# SPDX-License-Identifier: Apache-2.0
"""The glintbake Python module: asset information, vectorised queries against their one-row forms,
sampling consistency, errors carrying exit codes and validator ids, and the bake entry points
(same options as the tools, progress, cancellation)."""
import os
import struct
import threading

import numpy as np
import pytest

import glintbake

FORMAT_DIR = os.path.join(os.environ.get("GLINTBAKE_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", "..")),
                          "tests", "format")
PYRAMID = os.path.join(FORMAT_DIR, "v1_0_ndf_pyramid.gbk")
TENSOR = os.path.join(FORMAT_DIR, "v1_0_tensor_ndf.gbk")
LTC = os.path.join(FORMAT_DIR, "v1_0_ltc_table.gbk")
needs_bake = pytest.mark.skipif(not glintbake.has_bake, reason="module built without the baking library")


def test_asset_information():
    asset = glintbake.open(PYRAMID)
    assert asset.kind == "ndf-pyramid"
    assert asset.kind_code == 1
    assert asset.resolution == 4
    assert asset.map_size == (8, 8)
    assert asset.wrap == "repeat"
    r = asset.footprint_range
    assert 0 < r["pyramid_min_sigma"] < r["pyramid_max_sigma"]
    assert r["exact_max_sigma"] == 0
    assert asset.metadata["asset_kind"] == "ndf-pyramid"
    assert glintbake.__version__.count(".") == 2


@pytest.mark.parametrize("path", [PYRAMID, TENSOR])
def test_batches_equal_single_queries(path):
    asset = glintbake.open(path)
    rng = np.random.default_rng(7)
    n = 500
    fp = np.column_stack([rng.uniform(0, 8, n), rng.uniform(0, 8, n), rng.uniform(0.5, 6, n)])
    s = rng.uniform(-0.9, 0.9, (n, 2))
    batch = asset.eval(fp, s)
    assert batch.shape == (n,) and batch.dtype == np.float64
    single = np.array([asset.eval(fp[i], s[i])[0] for i in range(0, n, 50)])
    np.testing.assert_array_equal(batch[::50], single)
    # One footprint row shared by every point.
    shared = asset.eval(fp[3], s)
    np.testing.assert_array_equal(shared[3], batch[3])
    assert np.all(batch >= 0)


def test_sample_pdf_and_average():
    asset = glintbake.open(PYRAMID)
    rng = np.random.default_rng(1)
    fp = np.array([4.0, 4.0, 2.0])
    u = rng.uniform(0, 1, (2000, 2))
    points, pdf = asset.sample(fp, u)
    assert points.shape == (2000, 2)
    np.testing.assert_array_equal(asset.pdf(fp, points), pdf)  # bit for bit
    mass = asset.mass(fp)[0]
    np.testing.assert_allclose(asset.eval(fp, points) / mass, pdf, rtol=1e-12)  # sampling normalises by the mass
    full = asset.average(fp, np.array([-1.0, -1.0, 1.0, 1.0]))[0]
    assert full * 4.0 == pytest.approx(mass, rel=1e-9)
    image = asset.image(4.0, 4.0, 2.0)
    assert image.shape == (4, 4) and image.dtype == np.float32


@pytest.mark.skipif("address" not in os.environ.get("GLINTBAKE_SANITIZE", ""), reason="not an ASan build")
def test_runs_under_address_sanitizer():
    """In an ASan build these tests prove something only if the interpreter carries the sanitizer
    runtime and the module is instrumented."""
    with open("/proc/self/maps") as maps:
        assert "libasan" in maps.read()
    with open(glintbake._glintbake.__file__, "rb") as module:
        assert b"__asan_init" in module.read()


def test_refused_queries_are_nan_and_bad_shapes_raise():
    asset = glintbake.open(PYRAMID)
    values = asset.eval(np.array([[4.0, 4.0, -1.0], [4.0, 4.0, 1.0]]), np.array([0.1, 0.1]))
    assert np.isnan(values[0]) and not np.isnan(values[1])
    with pytest.raises(ValueError):
        asset.eval(np.zeros((3, 2)), np.zeros((3, 2)))
    with pytest.raises(ValueError):
        asset.eval(np.zeros((3, 3)), np.zeros((4, 2)))


def test_queries_from_threads():
    asset = glintbake.open(TENSOR)
    fp = np.array([0.5, 0.5, 1.0])
    s = np.random.default_rng(3).uniform(-1, 1, (20000, 2))
    expected = asset.eval(fp, s)
    results = [None] * 4

    def work(i):
        results[i] = asset.eval(fp, s)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        np.testing.assert_array_equal(r, expected)


def test_open_errors_carry_exit_code_and_message_id(tmp_path):
    with pytest.raises(glintbake.Error) as missing:
        glintbake.open(tmp_path / "missing.gbk")
    assert missing.value.exit_code == 2 and missing.value.message_id == 1001
    original = open(PYRAMID, "rb").read()
    for at in range(128, len(original) - 64, 64):  # the first byte of each section in turn
        data = bytearray(original)
        data[at] ^= 0x5A
        try:
            glintbake.Asset.from_bytes(bytes(data))
        except glintbake.Error as corrupt:
            assert corrupt.exit_code == 3 and corrupt.message_id > 0
            break
    else:
        pytest.fail("no corrupted section was refused")
    with pytest.raises(glintbake.Error) as other:
        glintbake.open(LTC)
    assert other.value.exit_code == 5 and "ltc-table" in str(other.value)  # as glintquery: wrong kind


def write_pfm(path, size):
    """A small bumpy normal map as a 3-channel PFM (bottom row first)."""
    y, x = np.mgrid[0:size, 0:size]
    nx = 0.3 * np.sin(x * 0.9) * np.cos(y * 0.4)
    ny = 0.3 * np.cos(x * 0.3 + y * 0.7)
    nz = np.sqrt(1 - nx ** 2 - ny ** 2)
    pixels = np.stack([nx, ny, nz], axis=-1)[::-1].astype("<f4")
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (size, size))
        f.write(pixels.tobytes())
    return str(path)


@needs_bake
def test_ndfgen_and_tensorpack(tmp_path):
    m = write_pfm(tmp_path / "m.pfm", 32)
    calls = []
    out = str(tmp_path / "m.gbk")
    summary = glintbake.ndfgen(m, output=out, ndf_res=16, stride=8, sigma0=4, threads=2,
                               progress=lambda label, done, total: calls.append((label, done, total)))
    assert summary["tool"] == "ndfgen" or "levels" in str(summary)
    assert calls and all(total > 0 for _, _, total in calls)
    asset = glintbake.open(out)
    assert asset.kind == "ndf-pyramid" and asset.map_size == (32, 32)
    assert asset.metadata["parameters"]["ndf_res"] == 16
    assert asset.mass(np.array([16.0, 16.0, 6.0]))[0] == pytest.approx(1.0, abs=0.05)

    packed = str(tmp_path / "t.gbk")
    glintbake.tensorpack(out, output=packed, rank=4, block=8)
    assert glintbake.open(packed).kind == "tensor-ndf"


@needs_bake
def test_bake_errors_and_cancellation(tmp_path):
    m = write_pfm(tmp_path / "m.pfm", 32)
    out = tmp_path / "c.gbk"
    with pytest.raises(glintbake.Error) as bad:
        glintbake.ndfgen(m, output=str(out), ndf_res=16, no_such_option=3)
    assert bad.value.exit_code == 1
    with pytest.raises(glintbake.Error) as io:
        glintbake.ndfgen(str(tmp_path / "missing.pfm"), output=str(out), ndf_res=16)
    assert io.value.exit_code == 2
    token = glintbake.Cancel()
    token.cancel()
    with pytest.raises(glintbake.Cancelled) as cancelled:
        glintbake.ndfgen(m, output=str(out), ndf_res=16, stride=8, sigma0=4, cancel=token)
    assert cancelled.value.exit_code == 4
    assert not out.exists()


@needs_bake
def test_ltcfit_table(tmp_path):
    out = str(tmp_path / "ltc.gbk")
    glintbake.ltcfit_table(output=out, size=4, samples=8)
    with pytest.raises(glintbake.Error) as wrong:
        glintbake.open(out)  # an LTC table is not an NDF asset
    assert wrong.value.exit_code == 5
