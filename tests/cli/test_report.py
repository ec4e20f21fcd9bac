"""The HTML report (scripts/make-report.py) on a small example map, checked in a real headless
browser: the page loads and every <img> decodes (the page's script records the counts on <body>)."""

import json
import os
import re
import shutil
import subprocess

import clitest

SCRIPT = os.path.join(clitest.SOURCE_DIR, "scripts", "make-report.py")


def find_browser():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


class ReportTest(clitest.ToolTestCase):
    def test_report_loads_in_a_browser(self):
        maps = self.path("maps")
        os.makedirs(maps)
        # A small stand-in for the example map keeps the test fast; the report generates nothing else.
        self.run_ok("mapgen", "flakes", "-o", os.path.join(maps, "flakes.exr"), "--size", "64", "--seed", "12",
                    "--cone", "12", "--cell", "8", "--quiet")
        out = self.path("report")
        proc = subprocess.run(["/usr/bin/python3", SCRIPT, "--bin", clitest.BIN_DIR, "--maps", maps, "--out", out,
                               "--only", "flakes", "--image-size", "32,32"], capture_output=True, text=True,
                              timeout=600)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        index = os.path.join(out, "index.html")
        with open(index) as f:
            page = f.read()
        sources = re.findall(r"<img src='([^']+)'", page)
        # 3 distances x (4 renders + 3 heat maps).
        self.assertEqual(len(sources), 21)
        for src in sources:
            self.assertTrue(os.path.exists(os.path.join(out, src)), src)
        with open(os.path.join(out, "report.json")) as f:
            report = json.load(f)
        far = report["assets"][0]["renders"]["far"]
        for mode in ("pyramid", "tensor16", "smooth"):
            self.assertGreater(far[mode]["speedup"], 0.0)
            self.assertGreaterEqual(far[mode]["relative_mse"], 0.0)

        browser = find_browser()
        self.assertIsNotNone(browser, "chromium is required (scripts/install-deps.sh --browser)")
        profile = self.path("profile")
        proc = subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--user-data-dir=" + profile,
                               "--virtual-time-budget=10000", "--dump-dom", "file://" + os.path.abspath(index)],
                              capture_output=True, text=True, timeout=120)
        self.assertEqual(proc.returncode, 0, proc.stderr[-2000:])
        body = re.search(r"<body([^>]*)>", proc.stdout)
        self.assertIsNotNone(body, "no <body> in the browser's DOM")
        total = re.search(r'data-images-total="(\d+)"', body.group(1))
        loaded = re.search(r'data-images-loaded="(\d+)"', body.group(1))
        self.assertIsNotNone(total, "the page's load script did not run")
        self.assertEqual(int(total.group(1)), len(sources))
        self.assertEqual(int(loaded.group(1)), len(sources), "some images failed to load")


if __name__ == "__main__":
    clitest.main()
