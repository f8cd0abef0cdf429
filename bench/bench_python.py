"""bench_python.py INPUT_DIR REFERENCE_DIR [--frames N]: the cost of the Python boundary in
`evaluate`. Times dynbench.evaluate with the built-in `none` and with a Python method that returns
its input (the same output, so the same scoring work), alternately, three times each, and prints
the median per frame and their difference. At 1080p make a window with
`build/release/bench/bench_evaluate --write-window DIR 8` (DIR/input, DIR/reference).

    PYTHONPATH=build/release/python python3 bench/bench_python.py DIR/input DIR/reference
"""
import argparse
import os
import statistics
import tempfile
import time

import dynbench


class Passthrough:
    name = "passthrough"

    def reset(self):
        pass

    def process(self, frame):
        return frame.channels["direct"] + frame.channels["indirect"]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("input")
    parser.add_argument("reference")
    parser.add_argument("--frames", type=int, default=8, help="the first N frames (default 8)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folders = {}
        for key, source in (("input", args.input), ("reference", args.reference)):
            folders[key] = os.path.join(tmp, key)
            os.mkdir(folders[key])
            for frame in sorted(f for f in os.listdir(source) if f.startswith("frame_"))[: 2 * args.frames]:
                os.symlink(os.path.abspath(os.path.join(source, frame)), os.path.join(folders[key], frame))
        frames = len(os.listdir(folders["input"])) // 2
        first = dynbench.read_frame(os.path.join(folders["input"], sorted(os.listdir(folders["input"]))[0]))
        times = {"none": [], "python": []}
        for _ in range(3):
            for key, method in (("none", "none"), ("python", Passthrough())):
                start = time.perf_counter()
                dynbench.evaluate(folders["input"], folders["reference"], methods=[method])
                times[key].append(1000 * (time.perf_counter() - start) / frames)
    none, python = statistics.median(times["none"]), statistics.median(times["python"])
    print(f"{first.width}x{first.height}, {frames} frames, median of 3 runs, ms per frame (reading, method, scoring)")
    print(f"none (built-in)          {none:8.1f}")
    print(f"passthrough (Python)     {python:8.1f}")
    print(f"the Python boundary      {python - none:8.1f}  ({(python - none) / none:+.1%})")


if __name__ == "__main__":
    main()
