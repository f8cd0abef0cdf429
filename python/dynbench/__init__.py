"""dynbench: dynamic benchmarks for temporal rendering, from Python (docs/python.md).

The functions are the library's own (a compiled module, ``dynbench._core``); each returns the
document the CLI's ``--json`` writes for the same arguments, as a dict.

    import dynbench
    frame = dynbench.read_frame("frames/frame_00000.exr")
    frame.channels["N"].shape          # (height, width, 3), float32
    scores = dynbench.evaluate("noisy/", "converged/", methods=["none", MyMethod()])
"""
import os as _os

# The image module (OpenImageIO) that the library loads on first use: the dynbench executable finds
# it beside itself; an installed package is at PREFIX/lib/python3.X/dist-packages/dynbench and the
# module at PREFIX/lib/dynbench (from the build tree the library knows its build path).
_image_module = _os.path.normpath(_os.path.join(_os.path.dirname(__file__), "..", "..", "..", "dynbench", "libdynbench_image.so"))
if _os.path.isfile(_image_module):
    _os.environ.setdefault("DYNBENCH_IMAGE_MODULE", _image_module)

from ._core import Error, Frame, compare, discard, evaluate, read_frame, stats, suite_records, suite_score
from ._core import _list_frames

__all__ = ["Error", "Frame", "compare", "discard", "evaluate", "frames", "read_frame", "stats", "suite_records", "suite_score"]


def frames(dir):
    """The frames of a folder (frame_NNNNN.exr + frame_NNNNN.json), read one at a time in frame order."""
    for image in _list_frames(dir):
        yield read_frame(image)
