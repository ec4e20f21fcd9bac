# SPDX-License-Identifier: Apache-2.0
"""Shared helpers for the command-line tests: run a tool, check its exit code and stderr, validate
--json output against the schemas in schemas/, and check that failures leave no output behind.

Tests import this module (PYTHONPATH is set by CTest) and use unittest."""

import hashlib
import json
import os
import subprocess
import tempfile
import unittest

BIN_DIR = os.environ.get("GLINTBAKE_BIN_DIR", "")
SOURCE_DIR = os.environ.get("GLINTBAKE_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
SCHEMA_DIR = os.path.join(SOURCE_DIR, "schemas")

# Documented exit codes (README.md).
OK, BAD_ARGS, IO, INVALID, RUNTIME, UNSUPPORTED, DIFFERENCES = 0, 1, 2, 3, 4, 5, 7


def tool_path(name):
    return os.path.join(BIN_DIR, name)


# Set (by CTest) to the sanitizers the tools were built with, e.g. "address,undefined".
SANITIZE = os.environ.get("GLINTBAKE_SANITIZE", "")


def run(tool, *args, stdin=None, timeout=600, env=None, limits=None):
    """Runs a tool; returns (exit code, stdout, stderr) as text. limits: {resource.RLIMIT_*: bytes}
    applied to the tool alone (e.g. RLIMIT_FSIZE as `ulimit -f` sets it, RLIMIT_AS for memory).
    Under ASan an address-space limit is not applied (its shadow memory alone reserves terabytes
    of addresses): the normal build's run of the same test checks the memory bound."""
    full_env = dict(os.environ)
    if env:
        full_env.update(env)
    if limits and "address" in SANITIZE:
        import resource
        limits = {which: value for which, value in limits.items() if which != resource.RLIMIT_AS}

    def apply_limits():
        import resource
        for which, value in (limits or {}).items():
            resource.setrlimit(which, (value, value))

    proc = subprocess.run([tool_path(tool)] + [str(a) for a in args], input=stdin, capture_output=True,
                          text=isinstance(stdin, str) or stdin is None, timeout=timeout, env=full_env,
                          preexec_fn=apply_limits if limits else None)
    if not isinstance(proc.stdout, str):
        return proc.returncode, proc.stdout.decode("utf-8", "replace"), proc.stderr.decode("utf-8", "replace")
    return proc.returncode, proc.stdout, proc.stderr


def load_schema(name):
    with open(os.path.join(SCHEMA_DIR, name)) as f:
        return json.load(f)


def validate(document, schema_name):
    """Validates a parsed JSON document against schemas/<schema_name>; schemas may refer to each
    other by file name."""
    import jsonschema
    schema = load_schema(schema_name)
    cls = jsonschema.validators.validator_for(schema)
    try:
        from referencing import Registry, Resource  # jsonschema >= 4.18
        resources = []
        for fn in sorted(os.listdir(SCHEMA_DIR)):
            if fn.endswith(".json"):
                res = Resource.from_contents(load_schema(fn))
                resources.append((fn, res))
                if res.id():
                    resources.append((res.id(), res))
        cls(schema, registry=Registry().with_resources(resources)).validate(document)
    except ImportError:
        base = "file://" + os.path.abspath(SCHEMA_DIR) + "/"
        cls(schema, resolver=jsonschema.RefResolver(base_uri=base, referrer=schema)).validate(document)


def file_hash(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


class ToolTestCase(unittest.TestCase):
    """Base class: a fresh temporary directory per test, and assertion helpers."""

    def setUp(self):
        self._tmp = tempfile.TemporaryDirectory(prefix="glintbake-test-")
        self.tmp = self._tmp.name

    def tearDown(self):
        self._tmp.cleanup()

    def path(self, name):
        return os.path.join(self.tmp, name)

    def write(self, name, data):
        """Writes bytes to a file of the test directory; returns its path."""
        path = self.path(name)
        with open(path, "wb") as f:
            f.write(data)
        return path

    def run_ok(self, tool, *args, **kw):
        code, out, err = run(tool, *args, **kw)
        self.assertEqual(code, OK, f"{tool} {' '.join(map(str, args))} failed ({code}): {err}")
        return out, err

    def run_json(self, tool, *args, schema=None, **kw):
        out, _ = self.run_ok(tool, *args, "--json", **kw)
        doc = json.loads(out)
        if schema:
            validate(doc, schema)
        return doc

    def assert_fails(self, expected_code, tool, *args, outputs=(), **kw):
        """The tool fails with the expected code, one line on stderr naming the problem, and leaves
        none of `outputs` (nor any temporary file) in the test directory."""
        before = set(os.listdir(self.tmp))
        code, out, err = run(tool, *args, **kw)
        self.assertEqual(code, expected_code, f"{tool} {args}: expected exit {expected_code}, got {code}; stderr: {err}")
        lines = [l for l in err.splitlines() if l.strip()]
        self.assertEqual(len(lines), 1, f"expected a one-line error, got: {err!r}")
        self.assertIn("error", lines[0])
        for o in outputs:
            self.assertFalse(os.path.exists(o), f"{o} was left behind after a failure")
        after = set(os.listdir(self.tmp))
        leftovers = [f for f in after - before if ".tmp" in f]
        self.assertEqual(leftovers, [], "temporary files left behind")
        return err

    def mapgen(self, kind, name, *args):
        out = self.path(name)
        self.run_ok("mapgen", kind, "-o", out, "--quiet", *args)
        return out


def main():
    unittest.main(verbosity=2)
