"""A temporal method in NumPy, scored by dynbench: an exponential moving average of the radiance
with motion-vector reprojection (the nearest previous pixel), history kept only on the same object
with the same normal and clamped to the current 3x3 neighbourhood's range (as TAA does).

    python3 examples/python/ema.py dynbench-demo/runs/colos_bot/input dynbench-demo/runs/colos_bot/frames

or scored on every dataset of a finished suite (`dynbench suite`), its column added to the suite's
suite.json and suite.md (docs/suite.md, "Score your own method"):

    python3 examples/python/ema.py --suite smoke
    python3 examples/python/ema.py --suite smoke --check   # and each dataset's column against `evaluate`

`--check` runs `dynbench.evaluate` again on each dataset's stored input and reference and exits 1
unless its mean HDR-FLIP equals the suite's column exactly.
"""
import sys

import numpy as np

import dynbench


class Ema:
    name, parameters = "ema", {"alpha": 0.2, "normal_dot": 0.9}

    def reset(self):
        self.history = None

    def process(self, frame):
        c = frame.channels
        colour = c["direct"] + c["indirect"]
        if self.history is not None:
            # Where this pixel's sample was in the previous frame (docs/feature-buffers.md, motion).
            y, x = np.mgrid[0 : frame.height, 0 : frame.width] + 0.5
            jitter = frame.camera["jitter"] - self.jitter
            px = np.floor(x + jitter[0] + c["motion"][..., 0]).clip(0, frame.width - 1).astype(int)
            py = np.floor(y + jitter[1] + c["motion"][..., 1]).clip(0, frame.height - 1).astype(int)
            same = (c["hit"][..., 0] > 0) & (self.id[py, px] == c["id"][..., 0]) & ((self.normal[py, px] * c["N"]).sum(-1) > 0.9)
            padded = np.pad(colour, ((1, 1), (1, 1), (0, 0)), mode="edge")
            shifts = [padded[dy : dy + frame.height, dx : dx + frame.width] for dy in range(3) for dx in range(3)]
            history = self.history[py, px].clip(np.min(shifts, axis=0), np.max(shifts, axis=0))
            colour = np.where(same[..., None], 0.2 * colour + 0.8 * history, colour)
        self.history, self.jitter, self.id, self.normal = colour, frame.camera["jitter"], c["id"][..., 0], c["N"]
        return colour


def score_suite(folder, check=False):
    suite = dynbench.suite_score(folder, methods=[Ema()])
    print(f"{'dataset':<20} {'none':>8} {'ema':>8} {'ema/none':>9}" + (f" {'evaluate':>9}" if check else "") + "   (mean HDR-FLIP over the window)")
    differs = 0
    for d in suite["datasets"]:
        e = d["errors"]
        line = f"{d['name']:<20} {e['none']['flip']:8.4f} {e['ema']['flip']:8.4f} {e['ema']['flip_ratio_to_none']:9.3f}"
        if check:
            run = f"{folder}/{d['run']}"
            again = dynbench.evaluate(f"{run}/input", f"{run}/frames", methods=[Ema()])["methods"][0]["mean"]["flip"]["mean"]
            same = again == e["ema"]["flip"]
            differs += not same
            line += f" {again:9.4f}" + ("" if same else f"  differs by {again - e['ema']['flip']:.3g}")
        print(line)
    if check:
        print(f"{len(suite['datasets'])} datasets, {differs} differ from evaluate")
    return differs == 0


if __name__ == "__main__":
    if sys.argv[1] == "--suite":
        sys.exit(0 if score_suite(sys.argv[2], check="--check" in sys.argv[3:]) else 1)
    scores = dynbench.evaluate(sys.argv[1], sys.argv[2], methods=["none", "accumulate", Ema()])
    print(f"{'method':<12} {'HDR-FLIP':>9} {'PSNR (dB)':>10} {'warped error change':>20}   (means over frames)")
    for method in scores["methods"]:
        mean = method["mean"]
        print(f"{method['name']:<12} {mean['flip']['mean']:9.4f} {mean['psnr']['mean']:10.2f} {mean['warped_error_change']['mean']:20.4f}")
