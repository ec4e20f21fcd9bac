# SPDX-License-Identifier: Apache-2.0
"""Hostile conditions a studio's unattended CI meets: a file-size limit (ulimit -f) on every writer,
a depfile that cannot be written, containers whose declared sizes would cost gigabytes, deeply
nested metadata and batch lines holding NUL bytes. Each must give a one-line error, the documented
exit code, bounded memory and nothing left behind."""

import json
import os
import random
import resource

import clitest
from clitest import INVALID, IO, OK
from containers import (CODEC_ZSTD, SECTION_IMAGE, SECTION_METADATA, build_container, image_payload, metadata,
                        read_sections, zstd_rle_frame)
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
