# SPDX-License-Identifier: Apache-2.0
"""Hostile conditions a studio's unattended CI meets: a file-size limit (ulimit -f) on every writer,
a depfile that cannot be written, containers whose declared sizes would cost gigabytes, deeply
nested metadata and batch lines holding NUL bytes. Each must give a one-line error, the documented
exit code, bounded memory and nothing left behind."""

import json
import os
import random
import resource
import struct
import zlib

import clitest
from clitest import INVALID, IO, OK
from containers import (CODEC_ZSTD, SECTION_IMAGE, SECTION_METADATA, build_container, image_payload, metadata,
                        read_sections, zstd_block_frame, zstd_rle_frame, zstd_with_window)
from test_ndfgen import write_pfm

KIND_NDF_PYRAMID, SECTION_NDF_CHUNK = 1, 17
# Far below every output below, far above nothing: writes past it fail with EFBIG.
FILE_LIMIT = {resource.RLIMIT_FSIZE: 1024}
# Address space for the hostile-container cases: the fixed tools need far less; the unfixed ones
# allocated the declared 3 GiB (or decoded 512 MiB of metadata) and die of it.
MEMORY_LIMIT = {resource.RLIMIT_AS: 768 << 20}
NDF = ["--ndf-res", "16", "--stride", "8", "--sigma0", "4", "--quiet"]


class WriterFailures(clitest.ToolTestCase):
    def setUp(self):
        super().setUp()
        self.map = self.mapgen("beckmann", "m.png", "--size", "32", "--seed", "3")
        self.asset = self.path("m.gbk")
        self.run_ok("ndfgen", self.map, "-o", self.asset, *NDF)

    def assert_write_fails(self, out, tool, *args):
        err = self.assert_fails(IO, tool, *args, outputs=[out], limits=FILE_LIMIT)
        self.assertIn("File too large", err)

    def test_every_writer_reports_a_file_size_limit(self):
        out = self.path("out.gbk")
        self.assert_write_fails(out, "ndfgen", self.map, "-o", out, *NDF)
        self.assert_write_fails(out, "tensorpack", self.map, "-o", out, "--ndf-res", "16", "--stride", "8",
                                "--sigma0", "4", "--rank", "4", "--block", "16", "--quiet")
        self.assert_write_fails(out, "ltcfit", "table", "--size", "8", "--samples", "16", "-o", out, "--quiet")
        exr = self.path("out.exr")
        self.assert_write_fails(exr, "mapgen", "beckmann", "-o", exr, "--size", "32", "--quiet")
        big = self.path("big.gbk")  # 64 x 64 NDF images: an EXR well over the limit
        self.run_ok("ndfgen", self.map, "-o", big, "--ndf-res", "64", "--stride", "8", "--sigma0", "4", "--quiet")
        self.assert_write_fails(exr, "glintquery", "image", big, "--at", "16,16", "--sigma", "8", "-o", exr)
        self.assert_write_fails(exr, "ltcfit", "roughness", self.map, "--alpha-micro", "0.2", "-o", exr, "--quiet")
        rng = random.Random(1)
        image = self.write("image.gbk", build_container([
            (SECTION_METADATA, 0, metadata()),
            (SECTION_IMAGE, 1, image_payload(32, 32, 1, 1, [rng.random() for _ in range(1024)]))]))
        self.assert_write_fails(exr, "glintinfo", "export", image, "image:1", "-o", exr)

    def test_a_truncated_image_never_replaces_the_previous_one(self):
        exr = self.path("keep.exr")
        self.run_ok("mapgen", "flat", "-o", exr, "--size", "4", "--quiet")
        with open(exr, "rb") as f:
            before = f.read()
        self.assert_fails(IO, "mapgen", "beckmann", "-o", exr, "--size", "64", "--quiet", limits=FILE_LIMIT)
        with open(exr, "rb") as f:
            self.assertEqual(f.read(), before)

    def test_failed_depfile_removes_the_output(self):
        out = self.path("dep.gbk")
        err = self.assert_fails(IO, "ndfgen", self.map, "-o", out, *NDF, "--depfile", self.path("no/such/dir/x.d"),
                                outputs=[out])
        self.assertIn("x.d", err)


class HostileContainers(clitest.ToolTestCase):
    def test_declared_section_size_is_checked_against_the_frame_before_allocating(self):
        # 3 GiB declared by raw_size and by the frame header; the frame's blocks make 1,000 bytes.
        bomb = self.write("bomb.gbk", build_container([
            (SECTION_METADATA, 0, metadata()),
            (SECTION_IMAGE, 1, zstd_rle_frame(3 << 30, produced=1000), CODEC_ZSTD, 3 << 30)]))
        self.assertLess(os.path.getsize(bomb), 10_000)
        code, out, err = clitest.run("glintinfo", "validate", bomb, "--json", limits=MEMORY_LIMIT)
        self.assertEqual(code, INVALID, err)
        self.assertIn(4003, [m["id"] for m in json.loads(out)["messages"]])
        self.assert_fails(INVALID, "glintinfo", "export", bomb, "image:1", "-o", self.path("x.exr"),
                          outputs=[self.path("x.exr")], limits=MEMORY_LIMIT)
        self.assert_fails(INVALID, "glintinfo", "diff", bomb, bomb, limits=MEMORY_LIMIT)

    def test_a_gibibyte_section_is_validated_and_compared_in_bounded_memory(self):
        # Honest 1 GiB image sections in a few KB: a GIMG header in a raw block, RLE blocks of zero
        # floats, and a last raw block of two floats, in a 1 MiB window. Validated and compared as
        # they stream past (under the 768 MiB address limit; diff once held both sections whole),
        # with the same verdicts as sections read whole.
        side = 16384
        header = struct.pack("<6IQ", 0x474D4947, side, side, 1, 1, 0, 0)
        raw_size = len(header) + side * side * 4
        paths = {}
        for tail, verdict in ((struct.pack("<2f", 0.5, 1.0), OK), (struct.pack("<2f", float("nan"), float("inf")), INVALID)):
            frame = zstd_block_frame(raw_size, [("raw", header), ("rle", b"\0", raw_size - 32 - 8), ("raw", tail)],
                                     window_log=20)
            path = paths[verdict] = self.write(f"big{verdict}.gbk", build_container([
                (SECTION_METADATA, 0, metadata()), (SECTION_IMAGE, 1, frame, CODEC_ZSTD, raw_size)]))
            self.assertLess(os.path.getsize(path), 50_000)
            code, out, err = clitest.run("glintinfo", "validate", path, "--json", limits=MEMORY_LIMIT)
            self.assertEqual(code, verdict, (out, err))
            ids = [m["id"] for m in json.loads(out)["messages"]]
            self.assertEqual(ids, [] if verdict == OK else [4006], out)
            if verdict == INVALID:
                self.assertIn("2 non-finite values", out)
        code, out, err = clitest.run("glintinfo", "diff", paths[OK], paths[OK], "--json", limits=MEMORY_LIMIT)
        self.assertEqual(code, OK, err)
        rows = json.loads(out)["sections"]
        self.assertEqual([(r["comparison"], r["status"]) for r in rows], [("metadata", "same"), ("image", "same")])
        self.assertEqual((rows[1]["max_abs_diff"], rows[1]["rel_l2"]), (0, 0))
        # A NaN against a number is an infinite difference (as when the sections are held whole).
        code, out, err = clitest.run("glintinfo", "diff", paths[OK], paths[INVALID], "--json", limits=MEMORY_LIMIT)
        self.assertEqual(code, clitest.DIFFERENCES, err)
        self.assertEqual(json.loads(out)["sections"][1]["max_abs_diff"], "inf")
        # The single-segment form of the same frame declares a 1 GiB window: refused, before
        # decoding (error-4010), by validate and diff alike.
        frame = zstd_block_frame(raw_size, [("raw", header), ("rle", b"\0", raw_size - 32)])
        wide = self.write("wide.gbk", build_container([
            (SECTION_METADATA, 0, metadata()), (SECTION_IMAGE, 1, frame, CODEC_ZSTD, raw_size)]))
        code, out, err = clitest.run("glintinfo", "validate", wide, "--json", limits=MEMORY_LIMIT)
        self.assertEqual(code, INVALID, err)
        self.assertEqual([m["id"] for m in json.loads(out)["messages"]], [4010], out)
        err = self.assert_fails(INVALID, "glintinfo", "diff", paths[OK], wide, limits=MEMORY_LIMIT)
        self.assertIn("wide.gbk: section 1: zstd frame window exceeds the reader limit of 128 MiB", err)
        # A frame that stops short of its content size is still error-4003, for validate and diff.
        frame = zstd_block_frame(raw_size, [("raw", header), ("rle", b"\0", raw_size - 64)], window_log=20)
        path = self.write("short.gbk", build_container([
            (SECTION_METADATA, 0, metadata()), (SECTION_IMAGE, 1, frame, CODEC_ZSTD, raw_size)]))
        code, out, err = clitest.run("glintinfo", "validate", path, "--json", limits=MEMORY_LIMIT)
        self.assertEqual(code, INVALID, err)
        self.assertIn(4003, [m["id"] for m in json.loads(out)["messages"]])
        err = self.assert_fails(INVALID, "glintinfo", "diff", paths[OK], path, limits=MEMORY_LIMIT)
        self.assertIn("short.gbk: section 1: section does not decode", err)

    def test_frames_of_windows_over_the_limit_are_refused_by_every_reader(self):
        # A real asset's ndf-chunk frame (compressed blocks) under a header declaring a 256 MiB
        # window, and, for a bomb, a 1 GiB window with 1 GiB of RLE blocks after the real ones
        # (a streaming decoder would need the whole GiB): every reader refuses both before
        # decoding, glintquery (the runtime) as glintinfo does.
        asset = self.path("m.gbk")
        self.run_ok("ndfgen", self.mapgen("beckmann", "m.png", "--size", "32", "--seed", "3"), "-o", asset, *NDF)
        with open(asset, "rb") as f:
            sections = read_sections(f.read())
        chunk = next(i for i, s in enumerate(sections) if s[0] == SECTION_NDF_CHUNK and s[3] == CODEC_ZSTD)
        stype, key, frame, _, raw_size = sections[chunk]
        for name, window_log, tail in (("w28.gbk", 28, 0), ("w30.gbk", 30, 1 << 30)):
            changed = list(sections)
            changed[chunk] = (stype, key, zstd_with_window(frame, window_log, tail), CODEC_ZSTD, raw_size + tail)
            path = self.write(name, build_container(changed, kind=KIND_NDF_PYRAMID))
            code, out, err = clitest.run("glintinfo", "validate", path, "--json", limits=MEMORY_LIMIT)
            self.assertEqual(code, INVALID, err)
            ids = [m["id"] for m in json.loads(out)["messages"]]
            self.assertEqual(ids[0], 4010, out)
            err = self.assert_fails(INVALID, "glintinfo", "diff", asset, path, limits=MEMORY_LIMIT)
            self.assertIn("zstd frame window exceeds the reader limit", err)
            self.assert_fails(INVALID, "glintquery", "point", path, "--at", "16,16", "--sigma", "8", "--s", "0,0",
                              limits=MEMORY_LIMIT)
        # The same blocks under a window of 2^27 bytes, the limit, read as the original.
        changed = list(sections)
        changed[chunk] = (stype, key, zstd_with_window(frame, 27), CODEC_ZSTD, raw_size)
        path = self.write("w27.gbk", build_container(changed, kind=KIND_NDF_PYRAMID))
        self.run_ok("glintinfo", "validate", path)
        query = ("--at", "16,16", "--sigma", "8", "--s", "0.1,0", "--json")
        self.assertEqual(json.loads(self.run_ok("glintquery", "point", path, *query)[0])["value"],
                         json.loads(self.run_ok("glintquery", "point", asset, *query)[0])["value"])

    def test_oversized_metadata_is_refused_before_decoding(self):
        # 512 MiB of metadata in a 20 KB file (honest RLE blocks): over the 16 MiB limit.
        big = zstd_rle_frame(512 << 20, byte=b" ")
        bomb = self.write("meta.gbk", build_container([(SECTION_METADATA, 0, big, CODEC_ZSTD, 512 << 20)]))
        code, out, err = clitest.run("glintinfo", "validate", bomb, "--json", limits=MEMORY_LIMIT)
        self.assertEqual(code, INVALID, err)
        self.assertIn(5016, [m["id"] for m in json.loads(out)["messages"]])
        err = self.assert_fails(INVALID, "glintinfo", "info", bomb, limits=MEMORY_LIMIT)
        self.assertIn("16 MiB", err)
        # Two such files are not "the same": diff refuses them.
        other = self.write("meta2.gbk", open(bomb, "rb").read())
        err = self.assert_fails(INVALID, "glintinfo", "diff", bomb, other, limits=MEMORY_LIMIT)
        self.assertIn("16 MiB", err)

    def test_deeply_nested_metadata(self):
        deep = b'{"schema":"glintbake.container-metadata/1","x":' + b"[" * 200_000 + b"]" * 200_000 + b"}"
        path = self.write("deep.gbk", build_container([(SECTION_METADATA, 0, deep)]))
        code, out, err = clitest.run("glintinfo", "info", path, "--json", limits=MEMORY_LIMIT)
        self.assertEqual(code, OK, err)
        self.assertIsInstance(json.loads(out)["metadata"], str)  # shown as text, not expanded
        code, out, err = clitest.run("glintinfo", "validate", path, "--json", limits=MEMORY_LIMIT)
        self.assertEqual(code, INVALID, err)
        self.assertIn(5003, [m["id"] for m in json.loads(out)["messages"]])
        err = self.assert_fails(INVALID, "glintinfo", "diff", path, path, limits=MEMORY_LIMIT)
        self.assertIn("5003", err)


def png_file(width, height, idat=b"", colour_type=2, bit_depth=8, after_ihdr=b""):
    """A PNG whose header declares width x height and whose IDAT holds `idat` (default: an empty,
    finished zlib stream), however little that is; `after_ihdr`: raw bytes put between IHDR and IDAT."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    ihdr = struct.pack(">IIBBBBB", width, height, bit_depth, colour_type, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + after_ihdr + chunk(b"IDAT", idat or zlib.compress(b"")) +
            chunk(b"IEND", b""))


def tiff_file(width, height, extra_tag):
    """A little-endian 8-bit RGB TIFF of one uncompressed strip, with one more IFD entry
    (tag, type, count, offset) whose data may lie anywhere, in the file or beyond it."""
    strip = width * height * 3
    entries = sorted([(256, 4, 1, width), (257, 4, 1, height), (258, 3, 1, 8), (259, 3, 1, 1), (262, 3, 1, 2),
                      (273, 4, 1, 300), (277, 3, 1, 3), (278, 4, 1, height), (279, 4, 1, strip), extra_tag])
    ifd = struct.pack("<H", len(entries)) + b"".join(struct.pack("<HHII", *e) for e in entries) + struct.pack("<I", 0)
    head = (b"II*\0" + struct.pack("<I", 8) + ifd).ljust(300, b"\0")
    return head + bytes([128, 128, 255]) * (width * height)


def exr_file(width, height, compression, first=b""):
    """A scanline OpenEXR file of three half channels whose header declares width x height and
    whose line offset table is all zeros: no chunk of pixels at all. compression: 3 zip, 4 piz.
    `first`: bytes put before the header's attributes."""
    def attr(name, kind, data):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(data)) + data
    channels = b"".join(c + b"\0" + struct.pack("<iB3xii", 1, 0, 1, 1) for c in (b"B", b"G", b"R")) + b"\0"
    box = struct.pack("<4i", 0, 0, width - 1, height - 1)
    header = (struct.pack("<ii", 20000630, 2) + first + attr("channels", "chlist", channels) +
              attr("compression", "compression", bytes([compression])) + attr("dataWindow", "box2i", box) +
              attr("displayWindow", "box2i", box) + attr("lineOrder", "lineOrder", b"\0") +
              attr("pixelAspectRatio", "float", struct.pack("<f", 1.0)) +
              attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0)) +
              attr("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    lines = {3: 16, 4: 32}[compression]
    return header + b"\0" * 8 * ((height + lines - 1) // lines)


class HostileImages(clitest.ToolTestCase):
    """Normal maps whose headers declare far more texels than their bytes can hold are refused by
    every tool that reads one (exit 3, one line naming the file), before the map is allocated: the
    address-space limit is far below the ~800 MB an 8192 x 8192 map of floats costs."""

    def hostile_files(self):
        files = {"tiny.png": png_file(8192, 8192)}
        # 1.5 KB of a real deflate stream of zero rows, cut short: 60 of the 8192 rows.
        z = zlib.compressobj(9)
        rows = z.compress(b"\0" * (1 + 8192 * 3) * 60) + z.flush(zlib.Z_SYNC_FLUSH)
        files["cut.png"] = png_file(8192, 8192, idat=rows)
        files["zip.exr"] = exr_file(8192, 8192, 3)  # bounded ratio: refused from its size
        files["piz.exr"] = exr_file(8192, 8192, 4)  # unbounded ratio: its last row is read first
        # A 64 x 64 file whose first attribute declares a 1.8 GB string (OpenEXR allocates it).
        files["attr.exr"] = exr_file(64, 64, 3, first=b"Software\0string\0" + struct.pack("<i", 0x6E000000))
        # A 4 x 4 PNG with a chunk declaring 1.9 GB (libpng allocates a chunk at its declared length).
        files["chunk.png"] = png_file(4, 4, after_ihdr=struct.pack(">I", 0x6F660000) + b"tEXtComment\0" + b"x" * 16)
        return {name: self.write(name, data) for name, data in files.items()}

    EXPECTED = {"tiny.png": "cannot hold the declared 8192x8192 image", "cut.png": "1032:1",
                "zip.exr": "cannot hold the declared 8192x8192 image", "piz.exr": "corrupt or truncated",
                "attr.exr": "attribute 'Software' declares 1845493760 bytes",
                "chunk.png": "PNG chunk 'tEXt' declares 1868955648 bytes"}

    def test_every_ingesting_tool_refuses_before_allocating(self):
        files = self.hostile_files()
        self.assertLess(os.path.getsize(files["tiny.png"]), 100)
        self.assertLess(os.path.getsize(files["cut.png"]), 2000)
        gbk, exr = self.path("out.gbk"), self.path("out.exr")
        for name, path in files.items():
            for args in (("ndfgen", path, "-o", gbk, *NDF),
                         ("tensorpack", path, "-o", gbk, *NDF, "--rank", "4", "--block", "16"),
                         ("glintref", "ndf", path, "--at", "8,8", "--sigma", "2", "--s", "0,0"),
                         ("ltcfit", "roughness", path, "--alpha-micro", "0.2", "-o", exr, "--quiet"),
                         ("wangtile", path, "-o", gbk, "--quiet"),
                         ("tinyexample", path, "-o", gbk, "--quiet")):
                err = self.assert_fails(INVALID, *args, outputs=[gbk, exr], limits=MEMORY_LIMIT)
                self.assertIn(name, err)
                self.assertIn(self.EXPECTED[name], err)

    def test_tiff_tags_beyond_the_file_cost_no_memory(self):
        # TIFF has no walk of its own before decoding: libtiff checks a tag's data against the file
        # before allocating it. A 4 x 4 map whose description declares 2 GB (ASCII, or UNDEFINED as an
        # ICC profile) reads in bounded memory; its pixels are whole, so it bakes.
        gbk = self.path("out.gbk")
        for tag in ((270, 2, 0x7FFFFFF0, 200), (34675, 7, 0x7FFFFFF0, 200)):
            path = self.write("tag%d.tif" % tag[0], tiff_file(4, 4, tag))
            self.assertLess(os.path.getsize(path), 400)
            for args in (("ndfgen", path, "-o", gbk, *NDF),
                         ("glintref", "ndf", path, "--at", "2,2", "--sigma", "1", "--s", "0,0")):
                code, out, err = clitest.run(*args, limits=MEMORY_LIMIT)
                self.assertEqual(code, OK, err)

    def test_manifest_assets_fail_alike(self):
        files = self.hostile_files()
        manifest = self.write("m.json", json.dumps({
            "schema": "glintbake.manifest/1", "defaults": {"tool": "ndfgen", "options": {"ndf-res": 16, "stride": 8}},
            "assets": [{"name": n, "inputs": [n], "output": n + ".gbk"} for n in files]}).encode())
        code, out, err = clitest.run("glintbake", "bake", manifest, "--json", limits=MEMORY_LIMIT)
        self.assertEqual(code, clitest.RUNTIME, err)
        for asset in json.loads(out)["assets"]:
            self.assertEqual((asset["status"], asset["exit_code"]), ("failed", INVALID), asset)
            self.assertIn(asset["name"], asset["message"])
            self.assertFalse(os.path.exists(self.path(asset["name"] + ".gbk")))

    def test_highly_compressible_large_maps_still_load(self):
        # Constant 2048 x 2048 maps compress far better than real ones; both formats still load.
        for name in ("flat.png", "flat.exr"):
            flat = self.mapgen("flat", name, "--size", "2048")
            out, _ = self.run_ok("glintref", "ndf", flat, "--at", "1024,1024", "--sigma", "1", "--s", "0,0", "--json")
            self.assertGreater(json.loads(out)["value"], 0.0)


class KindLayouts(clitest.ToolTestCase):
    """validate passes exactly the assets the runtime opens: a sound container whose NDF layout the
    runtime refuses is error-6004, with the runtime's own status, the one glintquery reports."""

    def assert_refused_alike(self, path):
        code, out, err = clitest.run("glintinfo", "validate", path, "--json")
        self.assertEqual(code, INVALID, err)
        messages = [m for m in json.loads(out)["messages"] if m["id"] == 6004]
        self.assertEqual(len(messages), 1, out)
        runtime_status = messages[0]["message"].rsplit(": ", 1)[1]
        err = self.assert_fails(INVALID, "glintquery", "point", path, "--at", "1,1", "--sigma", "2", "--s", "0,0")
        self.assertTrue(err.rstrip().endswith(runtime_status), (err, runtime_status))

    def test_missing_sections_and_a_chunk_without_its_image_header(self):
        m = self.mapgen("beckmann", "m.png", "--size", "32", "--seed", "3")
        good = self.path("good.gbk")
        self.run_ok("ndfgen", m, "-o", good, *NDF)
        self.run_ok("glintinfo", "validate", good)
        with open(good, "rb") as f:
            sections = read_sections(f.read())
        meta_only = self.write("meta-only.gbk", build_container(
            [s for s in sections if s[0] == SECTION_METADATA], kind=KIND_NDF_PYRAMID))
        self.assert_refused_alike(meta_only)
        chunk = next(i for i, s in enumerate(sections) if s[0] == SECTION_NDF_CHUNK)
        headless = list(sections)
        headless[chunk] = (SECTION_NDF_CHUNK, sections[chunk][1], b"\0" * 4096)
        self.assert_refused_alike(self.write("headless.gbk", build_container(headless, kind=KIND_NDF_PYRAMID)))


class MemoryBudget(clitest.ToolTestCase):
    def test_bakers_refuse_up_front_when_the_estimate_exceeds_max_memory(self):
        m = self.mapgen("beckmann", "m.png", "--size", "32", "--seed", "3")
        pack = ["--rank", "4", "--block", "16"]
        for tool, extra in (("ndfgen", []), ("tensorpack", pack)):
            out = self.path(tool + ".gbk")
            err = self.assert_fails(clitest.RUNTIME, tool, m, "-o", out, *NDF, *extra, "--max-memory", "64K",
                                    outputs=[out])
            self.assertIn("more than --max-memory 64K", err)
            self.assert_fails(clitest.BAD_ARGS, tool, m, "-o", out, *NDF, *extra, "--max-memory", "lots",
                              outputs=[out])
            self.run_ok(tool, m, "-o", out, *NDF, *extra, "--max-memory", "1G")


class TinyMaps(clitest.ToolTestCase):
    def test_one_texel_maps_are_refused_by_every_tool(self):
        one = self.path("one.pfm")
        write_pfm(one, 1, 1, "PF", [0.0, 0.0, 1.0])
        out = self.path("out.exr")
        for args in (("ltcfit", "roughness", one, "--alpha-micro", "0.2", "-o", out),
                     ("glintref", "ndf", one, "--at", "0.5,0.5", "--sigma", "1", "--s", "0,0")):
            err = self.assert_fails(INVALID, *args, outputs=[out])
            self.assertIn("1x1", err)


class BatchLines(clitest.ToolTestCase):
    def test_nul_byte_is_an_error_for_that_line_only(self):
        m = self.mapgen("beckmann", "m.png", "--size", "32", "--seed", "3")
        asset = self.path("m.gbk")
        self.run_ok("ndfgen", m, "-o", asset, *NDF)
        good = '{"op":"mass","x":16,"y":16,"sigma":4,"id":1}'
        bad = '{"op":"mass","x":16,"y":16,"sigma":4,"id":2}\0{"op":"frobnicate"}'
        code, out, err = clitest.run("glintquery", "batch", asset, stdin=good + "\n" + bad + "\n" + good + "\n")
        self.assertEqual(code, INVALID, err)
        answers = [json.loads(line) for line in out.splitlines()]
        self.assertEqual(len(answers), 3)
        self.assertIn("mass", answers[0])
        self.assertIn("NUL byte at column 45", answers[1]["error"])
        self.assertIn("mass", answers[2])


class BenchScript(clitest.ToolTestCase):
    def test_a_failing_benchmark_fails_the_run(self):
        import subprocess
        os.makedirs(self.path("bin"))
        programs = {"bench_ok": "echo 'BM_fine_median 10 ns 10 ns 100'",
                    "bench_crash": "echo 'BM_crash_median 1 ns 1 ns 1'; exit 3",
                    "bench_skip": "echo \"BM_skip ERROR OCCURRED: 'no input'\""}
        for name, body in programs.items():
            path = self.write("bin/" + name, ("#!/bin/sh\n" + body + "\n").encode())
            os.chmod(path, 0o755)
        script = os.path.join(clitest.SOURCE_DIR, "bench", "run.sh")
        proc = subprocess.run(["sh", script, self.tmp, "1"], capture_output=True, text=True, timeout=60)
        self.assertNotEqual(proc.returncode, 0, proc.stdout + proc.stderr)
        self.assertIn("bench_crash: FAILED", proc.stderr)
        self.assertIn("bench_skip: FAILED", proc.stderr)
        self.assertIn("BM_fine", proc.stdout)


if __name__ == "__main__":
    clitest.main()
