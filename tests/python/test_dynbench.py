"""The Python module against independent readers: OpenImageIO's own Python binding for the
frames, the dynbench CLI's --json documents for every function (docs/python.md)."""
import math
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio
import pytest

import dynbench
from conftest import ORBIT, ROOT, cli_json, dynbench_exe

# The feature-buffer contract's channels (docs/feature-buffers.md), written out here rather than
# taken from the module, so the test does not check the module against itself.
CONTRACT = {
    "P": ["P.X", "P.Y", "P.Z"], "N": ["N.X", "N.Y", "N.Z"], "direct": ["direct.R", "direct.G", "direct.B"],
    "indirect": ["indirect.R", "indirect.G", "indirect.B"], "albedo": ["albedo.R", "albedo.G", "albedo.B"], "Z": ["Z"],
    "id": ["id"], "motion": ["motion.X", "motion.Y"], "direct.var": ["direct.var"], "indirect.var": ["indirect.var"],
    "hit": ["hit"], "spp": ["spp"],
}


def oiio_channels(path):
    image = oiio.ImageInput.open(str(path))
    assert image, oiio.geterror()
    names = list(image.spec().channelnames)
    pixels = image.read_image(oiio.FLOAT)
    image.close()
    return names, pixels


def test_read_frame_equals_openimageio(frames):
    path = frames["input"] / "frame_00002.exr"
    frame = dynbench.read_frame(path)
    names, pixels = oiio_channels(path)
    assert (frame.width, frame.height, frame.frame) == (40, 24, 2)
    covered = set()
    for name, array in frame.channels.items():
        assert array.dtype == np.float32 and array.shape == (24, 40, len(CONTRACT[name])), name
        expected = np.stack([pixels[:, :, names.index(c)] for c in CONTRACT[name]], axis=-1)
        assert np.array_equal(array, expected), name
        covered.update(CONTRACT[name])
    assert covered == set(names), "every channel of the file is in .channels"
    assert frame.sidecar["frame"] == 2 and frame.sidecar["camera"]["jitter"] == list(frame.camera["jitter"])
    # The camera: clip = projection @ view @ world point; world is view's inverse.
    assert np.allclose(frame.camera["world"] @ frame.camera["view"], np.eye(4), atol=1e-9)
    assert np.allclose(frame.camera["world"][:3, 3], frame.camera["position"])


def test_frames_iterates_in_frame_order(frames):
    numbers = [f.frame for f in dynbench.frames(frames["reference"])]
    assert numbers == [0, 1, 2, 3, 4, 5]


def test_stats_equals_cli(tmp_path):
    assert dynbench.stats([ORBIT], fps=30) == cli_json(tmp_path, "stats", ORBIT, "--fps", 30)


def test_discard_equals_cli(frames, tmp_path):
    assert dynbench.discard(frames["reference"]) == cli_json(tmp_path, "discard", frames["reference"])
    assert dynbench.discard(frames["input"], geometry_test="bilinear", threshold_normal=0.2, radiance_test="plain") == cli_json(
        tmp_path, "discard", frames["input"], "--geometry-test", "bilinear", "--threshold-normal", 0.2, "--radiance-test", "plain")


def test_compare_paths_equal_cli_and_arrays_equal_paths(frames, tmp_path):
    reference, test = frames["reference"] / "frame_00003.exr", frames["input"] / "frame_00003.exr"
    by_path = dynbench.compare(reference, test)
    assert by_path == cli_json(tmp_path, "compare", reference, test)
    # The same images as arrays: a frame's radiance is direct + indirect (docs/metrics.md).
    radiance = lambda f: f.channels["direct"] + f.channels["indirect"]
    by_array = dynbench.compare(radiance(dynbench.read_frame(reference)), radiance(dynbench.read_frame(test)))
    assert by_array["reference"] is None and by_array["images"][0]["test"] is None
    for key in ("flip", "psnr", "ssim", "relmse", "smape", "exposures"):
        assert by_array["images"][0][key] == by_path["images"][0][key], key


def test_evaluate_equals_cli(frames, tmp_path):
    methods = ["none", "taa", "svgf"]
    assert dynbench.evaluate(frames["input"], frames["reference"], methods=methods) == cli_json(
        tmp_path, "evaluate", frames["input"], "--reference", frames["reference"], "--methods", ",".join(methods))


class Passthrough:
    """A Python method that returns its input's radiance: it must score exactly as `none`."""
    name = "passthrough"
    parameters = {"kind": "identity"}

    def __init__(self):
        self.resets = 0

    def reset(self):
        self.resets += 1

    def process(self, frame):
        return frame.channels["direct"] + frame.channels["indirect"]


def test_a_python_method_is_scored_as_a_builtin(frames):
    method = Passthrough()
    result = dynbench.evaluate(frames["input"], frames["reference"], methods=["none", method])
    none, passthrough = result["methods"]
    assert passthrough["name"] == "passthrough" and passthrough["parameters"] == {"kind": "identity"}
    assert method.resets == 1, "reset at the first frame (the orbit has no cuts)"
    assert len(passthrough["frames"]) == 6
    for a, b in zip(none["frames"], passthrough["frames"]):
        for key in ("flip", "psnr", "ssim", "relmse", "tpsnr", "trelmse", "warped_error_change"):
            assert a[key] == b[key], key
        assert b["history_use"] is None  # a Python method's history use is unknown


def test_bad_inputs_raise_with_the_library_message_and_status(frames, tmp_path):
    with pytest.raises(dynbench.Error) as e:
        dynbench.read_frame(tmp_path / "image.exr")
    assert e.value.status == 2 and "image.exr" in str(e.value) and "frame_NNNNN" in str(e.value)
    with pytest.raises(dynbench.Error) as e:
        dynbench.read_frame(tmp_path / "frame_00007.exr")
    assert e.value.status == 3 and "frame_00007" in str(e.value)
    with pytest.raises(dynbench.Error) as e:
        dynbench.discard(tmp_path / "missing")
    assert e.value.status == 3 and "missing" in str(e.value)
    with pytest.raises(dynbench.Error) as e:
        dynbench.discard(frames["input"], geometry_test="cubic")
    assert e.value.status == 2 and "geometry_test" in str(e.value) and "taps, bilinear" in str(e.value)
    bad = tmp_path / "broken.json"
    bad.write_text('{"asset": ')
    with pytest.raises(dynbench.Error) as e:
        dynbench.stats([bad])
    assert e.value.status == 4 and "broken.json" in str(e.value)
    nan = np.zeros((16, 16, 3), np.float32)
    nan[5, 7, 1] = np.nan
    with pytest.raises(dynbench.Error) as e:
        dynbench.compare(np.zeros((16, 16, 3)), nan)
    assert e.value.status == 5 and "pixel (7, 5) channel 1" in str(e.value)
    with pytest.raises(dynbench.Error) as e:
        dynbench.compare(np.zeros((16, 16, 3)), np.zeros((16, 15, 3)))
    assert e.value.status == 5 and "(16, 16, 3)" in str(e.value)


class WrongShape(Passthrough):
    name = "wrong_shape"

    def process(self, frame):
        return np.zeros((frame.height, frame.width), np.float32)


class Raises(Passthrough):
    name = "raises"

    def process(self, frame):
        raise ValueError(f"no output for frame {frame.frame}")


def test_bad_methods_raise(frames):
    run = lambda *methods: dynbench.evaluate(frames["input"], frames["reference"], methods=list(methods))
    with pytest.raises(dynbench.Error) as e:
        run(object())
    assert e.value.status == 2 and "reset()" in str(e.value)
    with pytest.raises(dynbench.Error) as e:
        run("bogus")
    assert e.value.status == 2 and "bogus" in str(e.value)
    with pytest.raises(dynbench.Error) as e:
        run(WrongShape())
    assert e.value.status == 5 and "wrong_shape" in str(e.value) and "frame 0" in str(e.value) and "(24, 40, 3)" in str(e.value)
    with pytest.raises(ValueError, match="no output for frame 0"):
        run("none", Raises())
    with pytest.raises(dynbench.Error) as e:
        run(Passthrough(), Passthrough())
    assert e.value.status == 2 and "passthrough" in str(e.value)


def test_example_is_steadier_and_less_noisy_than_none(frames):
    """examples/python/ema.py: a moving average with motion-vector reprojection. What it is for:
    less noise (PSNR above none's) and a steadier image (warped error change below none's). Its
    HDR-FLIP is higher than none's here (nearest-pixel resampling blurs edges; docs/python.md)."""
    result = subprocess.run([sys.executable, str(ROOT / "examples" / "python" / "ema.py"), str(frames["input"]), str(frames["reference"])],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    rows = {line.split()[0]: [float(v) for v in line.split()[1:4]] for line in result.stdout.splitlines()[1:]}
    assert set(rows) == {"none", "accumulate", "ema"}, result.stdout
    assert rows["ema"][1] > rows["none"][1] and rows["ema"][2] < rows["none"][2], result.stdout
