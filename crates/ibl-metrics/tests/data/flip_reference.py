"""Reference FLIP values for ibl-metrics' tests, from NVIDIA's implementation.

Run with NVIDIA's `flip-evaluator` (PyPI, version 1.7):

    python3 -m venv venv && venv/bin/pip install flip-evaluator==1.7 numpy
    venv/bin/python flip_reference.py > flip_reference.json

The image pairs are made from integer formulas whose values are exact in binary (multiples of
1/1024, or of 1/64 times a power of two), so `tests/flip_reference.rs` rebuilds them bit for bit in
Rust and compares its own FLIP with the numbers written here. Inputs are linear: LDR pairs are
passed with inputsRGB=False (values are display-linear in [0, 1], as ibl-metrics' LDR mode takes
them); HDR pairs use FLIP's default ACES tone mapper and its automatic exposures.
"""

import json

import flip_evaluator as flip
import numpy as np

W, H = 48, 32


def hash3(x, y, s):
    """The same 32-bit hash as the Rust test: wrapping products, xor."""
    m = 0xFFFFFFFF
    return ((x * 73856093) & m) ^ ((y * 19349663) & m) ^ ((s * 83492791) & m)


def image(f):
    img = np.zeros((H, W, 3), dtype=np.float32)
    for y in range(H):
        for x in range(W):
            for c in range(3):
                img[y, x, c] = f(x, y, c)
    return img


def gradient(x, y, c):
    return ((x * 16 + y * 8 + c * 200) % 1024) / 1024.0


def noisy_gradient(x, y, c):
    v = gradient(x, y, c) + ((hash3(x, y, c) % 64) - 32) / 1024.0
    return min(max(v, 0.0), 1.0)


def checker(shift):
    def f(x, y, c):
        return 0.8125 if ((x + shift) // 8 + y // 8) % 2 == 0 else 0.1875
    return f


def sky(x, y, c):
    return (200 + y * 4 + c * 30) / 1024.0


def sun(size, value):
    def f(x, y, c):
        if 30 <= x < 30 + size and 8 <= y < 8 + size:
            return value
        return sky(x, y, c)
    return f


def hdr_noise(x, y, c):
    return (hash3(x, y, c) % 1024) / 64.0


def hdr_noise_test(x, y, c):
    return hdr_noise(x, y, c) * (1.0 + ((hash3(y, x, c + 7) % 32) - 16) / 256.0)


PAIRS = {
    "ldr_noise": ("LDR", gradient, noisy_gradient),
    "ldr_edge": ("LDR", checker(0), checker(1)),
    "hdr_sun": ("HDR", sun(4, 512.0), sun(8, 128.0)),
    "hdr_noise": ("HDR", hdr_noise, hdr_noise_test),
}

# Pixels whose map values are recorded, (x, y).
PROBES = [(0, 0), (7, 3), (8, 8), (24, 16), (31, 10), (33, 9), (40, 30), (47, 31)]

out = {"flip_evaluator": "1.7", "width": W, "height": H, "ppd": 67.0, "pairs": {}}
for name, (mode, ref_f, test_f) in PAIRS.items():
    ref, test = image(ref_f), image(test_f)
    fmap, mean, params = flip.evaluate(
        ref, test, mode, inputsRGB=False, applyMagma=False, computeMeanError=True,
        parameters={"ppd": 67.0},
    )
    fmap = np.asarray(fmap).reshape(H, W)
    entry = {
        "mode": mode,
        "mean": float(mean),
        "pixels": [[x, y, float(fmap[y, x])] for (x, y) in PROBES],
    }
    if mode == "HDR":
        entry["start_exposure"] = float(params["startExposure"])
        entry["stop_exposure"] = float(params["stopExposure"])
        entry["exposures"] = int(params["numExposures"])
    out["pairs"][name] = entry
print(json.dumps(out, indent=2))
