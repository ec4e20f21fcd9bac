# SPDX-License-Identifier: Apache-2.0
"""The command-line contract every tool keeps: --help, --version, bad arguments, exit codes,
depfiles driving make, and determinism across thread counts."""

import os
import re
import shutil
import subprocess

import clitest
from clitest import ToolTestCase, run

# The tools the build defines (tools/CMakeLists.txt passes its list); every one must exist.
TOOLS = [t for t in os.environ.get("GLINTBAKE_TOOLS", "").split(",") if t]


class Contract(ToolTestCase):
    def test_tools_present(self):
        for t in ["glintinfo", "mapgen"]:
            self.assertIn(t, TOOLS)
        for t in TOOLS:
            self.assertTrue(os.path.exists(clitest.tool_path(t)), t + " is in the build's tool list but was not built")

    def test_help(self):
        for tool in TOOLS:
            code, out, err = run(tool, "--help")
            self.assertEqual(code, 0, tool)
            self.assertIn("Exit codes", out, tool)
            self.assertIn("--json", out, tool)

    def test_version(self):
        for tool in TOOLS:
            code, out, _ = run(tool, "--version")
            self.assertEqual(code, 0, tool)
            self.assertRegex(out.strip(), r"^glintbake %s \d+\.\d+\.\d+ \(container format \d+\.\d+\)$" % tool)

    def test_unknown_option_is_exit_1_one_line(self):
        for tool in TOOLS:
            self.assert_fails(clitest.BAD_ARGS, tool, "--definitely-not-an-option")

    def test_negative_thread_count_rejected(self):
        for tool in TOOLS:
            code, _, err = run(tool, "--threads", "-5", "--help")
            # --help wins when given; without it the bad value is an argument error.
            code, _, err = run(tool, "--threads", "-5")
            self.assertEqual(code, clitest.BAD_ARGS, f"{tool}: {err}")


@__import__("unittest").skipUnless(shutil.which("make"), "make is not installed")
class DepfileWithMake(ToolTestCase):
    """A Makefile driven by depfiles rebuilds exactly what an input change affects."""

    def test_incremental_build(self):
        self.assertIn("ndfgen", TOOLS)
        bin_dir = clitest.BIN_DIR
        makefile = self.path("Makefile")
        with open(makefile, "w") as f:
            f.write(
                "BIN := %s\n"
                "all: a.gbk b.gbk\n"
                "a.png:\n\t$(BIN)/mapgen beckmann -o $@ --size 32 --seed 1 --quiet\n"
                "b.png:\n\t$(BIN)/mapgen flakes -o $@ --size 32 --seed 2 --quiet\n"
                "%%.gbk: %%.png\n\t$(BIN)/ndfgen $< -o $@ --depfile $@.d --quiet --ndf-res 16 --levels 2\n"
                "-include $(wildcard *.d)\n" % bin_dir)
        def make(*args):
            p = subprocess.run(["make", "-C", self.tmp] + list(args), capture_output=True, text=True)
            self.assertEqual(p.returncode, 0, p.stderr)
            return p.stdout
        make()
        self.assertTrue(os.path.exists(self.path("a.gbk")))
        self.assertTrue(os.path.exists(self.path("a.gbk.d")))
        # Nothing to do the second time.
        q = subprocess.run(["make", "-q", "-C", self.tmp], capture_output=True)
        self.assertEqual(q.returncode, 0)
        # Touching one input rebuilds only its asset.
        mtime_b = os.path.getmtime(self.path("b.gbk"))
        os.utime(self.path("a.png"), (os.path.getmtime(self.path("a.png")) + 10,) * 2)
        out = make()
        self.assertIn("a.gbk", out)
        self.assertNotIn("b.gbk", out.replace("a.gbk", ""))
        self.assertEqual(os.path.getmtime(self.path("b.gbk")), mtime_b)


class Interrupt(ToolTestCase):
    """SIGINT, SIGTERM or even SIGKILL during a bake leaves neither the output nor a temporary file
    (the temporary container is anonymous where the file system allows, as here)."""

    def writing(self, pid):
        """True once the process holds a file open for writing in the test directory."""
        fd_dir = "/proc/%d/fd" % pid
        try:
            targets = [os.readlink(os.path.join(fd_dir, fd)) for fd in os.listdir(fd_dir)]
        except OSError:
            return False
        return any(t.startswith(self.tmp + "/") and not t.endswith("in.exr") for t in targets)

    def test_interrupted_bake_leaves_nothing(self):
        self.assertIn("ndfgen", TOOLS)
        import signal
        import time
        src = self.mapgen("scratches", "in.exr", "--size", "256", "--seed", "3")
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGKILL):
            out = self.path("out.gbk")
            proc = subprocess.Popen([clitest.tool_path("ndfgen"), src, "-o", out, "--quiet", "--stride", "2",
                                     "--sigma0", "2", "--levels", "6", "-j", "1"],
                                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            # Wait until the temporary container is open, then interrupt.
            deadline = time.time() + 30
            while time.time() < deadline and not self.writing(proc.pid):
                time.sleep(0.05)
            self.assertTrue(self.writing(proc.pid), "the bake never opened its output")
            proc.send_signal(sig)
            code = proc.wait(timeout=30)
            self.assertNotEqual(code, 0)
            self.assertEqual(sorted(os.listdir(self.tmp)), ["in.exr"])


if __name__ == "__main__":
    clitest.main()
