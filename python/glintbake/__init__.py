# SPDX-License-Identifier: Apache-2.0
"""glintbake: baked glinty-appearance assets from Python.

Queries (no Python loop per query; the GIL is released while a batch runs)::

    import glintbake, numpy as np
    asset = glintbake.open("brushed.gbk")
    fp = np.array([[64.0, 64.0, 4.0]])           # footprint rows (x, y, sigma) in texels
    s = np.random.uniform(-0.5, 0.5, (1000, 2))  # s-plane points (s_x, s_y)
    d = asset.eval(fp, s)                        # (1000,) densities; fp is shared by every row

Bakes, with the command-line tools' option names as keywords (``--sigma0 4`` is ``sigma0=4``,
a flag is ``True``)::

    glintbake.ndfgen("map.png", output="map.gbk", ndf_res=16, progress=print)
    glintbake.tensorpack("map.gbk", output="map-t.gbk", rank=8)
    glintbake.ltcfit_table(output="ggx.gbk", size=16)

Failures raise glintbake.Error with ``exit_code`` (the tools' exit codes), ``message_id`` (the
validator's id, 0 if none) and ``status``; a cancelled bake raises glintbake.Cancelled.
"""
import json as _json

from ._glintbake import Asset, Cancel, Error, __version__, has_bake  # noqa: F401
from . import _glintbake

__all__ = ["Asset", "Cancel", "Cancelled", "Error", "open", "ndfgen", "tensorpack", "ltcfit_table", "__version__"]


class Cancelled(Error):
    """A bake stopped by its Cancel token or by a progress callback returning False."""


def open(path):  # noqa: A001 (the module's verb, like gzip.open)
    """Opens an NDF asset file (ndf-pyramid, tensor-ndf, glitter) as an Asset."""
    return Asset.open(str(path))


def _metadata(self):
    """The container's metadata (generator, canonical parameters, inputs) as a dict."""
    return _json.loads(self.metadata_text) if self.metadata_text else {}


Asset.metadata = property(_metadata)


def _arguments(positional, options):
    """Command-line arguments from keyword options: name_with_underscores=value -> --name-with-underscores value."""
    args = [str(p) for p in positional]
    for key, value in options.items():
        if value is None or value is False:
            continue
        flag = ("-" if len(key) == 1 else "--") + key.replace("_", "-")
        if value is True:
            args.append(flag)
        elif isinstance(value, (list, tuple)):
            args.append(flag)
            args.extend(str(v) for v in value)
        else:
            args.extend([flag, str(value)])
    return args


def _run(tool, args, progress, cancel):
    if not has_bake:
        raise Error("this glintbake module was built without the baking library (runtime only)")
    code, message, summary, cancelled = _glintbake._run_tool(tool, args + ["--json"], progress, cancel)
    if code != 0:
        kind = Cancelled if cancelled else Error
        error = kind("%s: %s" % (tool, message or "failed with exit code %d" % code))
        error.exit_code = code
        error.message_id = 0
        error.status = "cancelled" if cancelled else "error"
        raise error
    return _json.loads(summary) if summary else {}


def ndfgen(map=None, *, progress=None, cancel=None, **options):  # noqa: A002 (the CLI's name)
    """Bakes an ndf-pyramid asset, as ``ndfgen MAP [options]``; returns its --json summary as a dict.

    progress(label, done, total) is called as the bake advances (return False to stop it); cancel is
    a glintbake.Cancel token."""
    return _run("ndfgen", _arguments([] if map is None else [map], options), progress, cancel)


def tensorpack(input, *, progress=None, cancel=None, **options):  # noqa: A002
    """Compresses a map or an ndf-pyramid asset into a tensor-ndf asset, as ``tensorpack INPUT [options]``."""
    return _run("tensorpack", _arguments([input], options), progress, cancel)


def ltcfit_table(*, progress=None, cancel=None, **options):
    """Fits an LTC table (ltc-table asset), as ``ltcfit table [options]``."""
    return _run("ltcfit", ["table"] + _arguments([], options), progress, cancel)
