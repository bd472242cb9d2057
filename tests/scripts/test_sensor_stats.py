"""scripts/sensor_stats.py and sensor_io.py (the sensor calibration's
measurements) on synthetic depth images with known noise, quantization,
holes, edges and incidence: a plane with Gaussian noise of 2 mm measures
about 2 mm, a depth quantized to 4 mm steps measures 4 mm steps, and so on.

They need numpy. Where the interpreter running the suite has none but
Debian's /usr/bin/python3 has (the project installs python3-numpy), the
whole module is run again under /usr/bin/python3 and must pass there."""
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
try:
    import numpy as np
    import sensor_io
    import sensor_stats
except ImportError:  # no numpy here
    np = None

SYSTEM_PYTHON = "/usr/bin/python3"
K = {"fx": 500.0, "fy": 500.0, "cx": 319.5, "cy": 239.5}


def plane(z0=1000.0, slope_u=0.0, slope_v=0.0, h=480, w=640):
    v, u = np.mgrid[0:h, 0:w].astype(np.float64)
    return z0 + slope_u * (u - w / 2) + slope_v * (v - h / 2)


def tilted_plane(z0, tilt_deg, K, h, w):
    """Exact depth of a plane through (0, 0, z0) turned by tilt_deg about the y axis."""
    v, u = np.mgrid[0:h, 0:w].astype(np.float64)
    t = np.radians(tilt_deg)
    n = np.array([np.sin(t), 0.0, np.cos(t)])
    ray = np.stack([(u - K["cx"]) / K["fx"], (v - K["cy"]) / K["fy"], np.ones_like(u)], axis=-1)
    return z0 * n[2] / (ray @ n)


@unittest.skipIf(np is None, "numpy missing here (run under /usr/bin/python3 by NumpyElsewhere)")
class Noise(unittest.TestCase):
    def test_plane_with_gaussian_noise_of_2mm_measures_2mm(self):
        rng = np.random.default_rng(1)
        d = plane(1000, 0.3, -0.2) + rng.normal(0, 2.0, (480, 640))
        s = sensor_stats.Stats()
        s.add(d, K)
        med = s.summary()["noise_mm"]["median"][2]  # bin 1000-1250
        self.assertAlmostEqual(med, 2.0, delta=0.1)

    def test_noise_grows_with_depth_bin(self):
        rng = np.random.default_rng(2)
        s = sensor_stats.Stats()
        for z, sigma in ((800, 1.0), (2100, 5.0)):
            s.add(plane(z) + rng.normal(0, sigma, (480, 640)), K)
        noise = s.summary()["noise_mm"]["median"]
        self.assertAlmostEqual(noise[1], 1.0, delta=0.06)   # 750-1000
        self.assertAlmostEqual(noise[6], 5.0, delta=0.3)    # 2000-2250

    def test_patches_across_a_depth_jump_are_rejected(self):
        d = plane(1000)
        d[:, 320:] = 1500  # a step of 500 mm, noise free
        zp, rms = sensor_stats.patch_noise(d)
        self.assertTrue(np.all(rms < 1e-6))
        self.assertEqual(len(zp), (480 // 7) * (640 // 7) - 480 // 7)  # the column of patches on the step


@unittest.skipIf(np is None, "numpy missing here")
class Quantization(unittest.TestCase):
    def test_steps_of_4mm_measure_4mm(self):
        d = np.round(plane(1100, 0.5, 0.3) / 4.0) * 4.0
        q = sensor_stats.quant_steps(d, sensor_stats.depth_bins())
        self.assertEqual(q[2], 4.0)
        self.assertTrue(np.isnan(q[10]))  # no depth there


@unittest.skipIf(np is None, "numpy missing here")
class Missing(unittest.TestCase):
    def test_random_holes_give_their_rate_and_none_at_edges(self):
        rng = np.random.default_rng(3)
        d = plane(1600)
        d[rng.random(d.shape) < 0.1] = 0
        s = sensor_stats.Stats()
        s.add(d, K)
        out = s.summary()
        self.assertAlmostEqual(out["missing"]["rate"][4], 0.1, delta=0.01)
        self.assertEqual(sum(out["edge_missing"]["pixels"]), 0)
        self.assertAlmostEqual(out["pooled"]["nonedge_missing"], 0.1, delta=0.01)

    def test_holes_next_to_a_jump_count_as_edge_missing(self):
        d = plane(1000)
        d[:, 320:] = 2000
        d[:, 319:321] = 0  # a 2 px band without depth at the step (both sides in the 7 x 7 window)
        near, missing, at_edge = sensor_stats.edge_missing(d)
        self.assertEqual(int(missing[at_edge].sum()), 2 * 480)
        self.assertEqual(int(missing[~at_edge].sum()), 0)

    def test_luminance_bins(self):
        d = plane(1000)
        lum = np.full(d.shape, 200.0)
        lum[:, :160] = 10.0
        d[:, :80] = 0  # half of the dark pixels have no depth
        s = sensor_stats.Stats()
        s.add(d, K, luminance=lum)
        rate = s.summary()["luminance_missing"]["rate"]
        self.assertAlmostEqual(rate[0], 0.5)
        self.assertEqual(rate[6], 0.0)


@unittest.skipIf(np is None, "numpy missing here")
class IncidenceAndEdges(unittest.TestCase):
    def test_block_incidence_recovers_the_tilt(self):
        narrow = {"fx": 500.0, "fy": 500.0, "cx": 31.5, "cy": 31.5}  # 64 x 64 px: rays within 4 deg of the axis
        for tilt in (20, 60, 80):
            ang, miss, tot = sensor_stats.block_incidence(tilted_plane(1500, tilt, narrow, 64, 64), narrow)
            self.assertEqual(len(ang), 64)
            self.assertLess(np.abs(ang - tilt).max(), 4.5, tilt)
            self.assertEqual(miss.sum(), 0)

    def test_mixed_pixels_between_fore_and_background_are_flying(self):
        d = plane(1000)
        d[:, 320:] = 2000
        _, pos = sensor_stats.edge_triplets(d)
        self.assertTrue(np.all((pos < 0.15) | (pos > 0.85)))  # a sharp edge: none in between
        d[:, 320] = 1500
        near, pos = sensor_stats.edge_triplets(d)
        between = (pos > 0.15) & (pos < 0.85)
        self.assertEqual(int(between.sum()), 480)
        s = sensor_stats.Stats()
        s.add(d, K)
        self.assertAlmostEqual(s.summary()["pooled"]["flying"], 480 / len(pos), places=3)


@unittest.skipIf(np is None, "numpy missing here")
class Io(unittest.TestCase):
    def test_lzf_literals_and_back_references(self):
        # "abcabcabc": 3 literals, then a back reference of length 6 at distance 3
        data = bytes([2]) + b"abc" + bytes([(4 << 5) | 0, 2])
        self.assertEqual(sensor_io.lzf_decompress(data, 9), b"abcabcabc")

    def test_binary_compressed_pcd_round_trip_and_intrinsics(self):
        h, w = 6, 8
        z = np.full((h, w), 1.25, dtype=np.float32)
        z[0, 0] = np.nan
        v, u = np.mgrid[0:h, 0:w]
        x = ((u - 3.5) * z / 525.0).astype(np.float32)
        y = ((v - 2.5) * z / 525.0).astype(np.float32)
        raw = x.tobytes() + y.tobytes() + z.tobytes()
        lzf = b"".join(bytes([len(raw[i:i + 32]) - 1]) + raw[i:i + 32] for i in range(0, len(raw), 32))
        header = ("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH %d\nHEIGHT %d\n"
                  "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\nDATA binary_compressed\n" % (w, h, w * h))
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "f.pcd")
            with open(path, "wb") as f:
                f.write(header.encode() + struct.pack("<II", len(lzf), len(raw)) + lzf)
            depth, Kr = sensor_io.read_pcd_depth(path)
        self.assertEqual(depth[0, 0], 0.0)
        self.assertAlmostEqual(depth[3, 3], 1250.0, places=3)
        self.assertAlmostEqual(Kr["fx"], 525.0, places=2)
        self.assertAlmostEqual(Kr["cx"], 3.5, places=3)
        self.assertAlmostEqual(Kr["cy"], 2.5, places=3)

    def test_txt_depth_frame_row_by_row_and_its_errors(self):
        src = {"format": "txt", "width": 3, "height": 2, "intrinsics": {"fx": 365.0, "fy": 365.0, "cx": 1.0,
                                                                          "cy": 0.5}}
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "d.txt")
            with open(path, "w") as f:
                f.write("0\n1000\n1001\n1500\n1501\n1502\n")
            depth, Kr, lum = sensor_io.read_frame(path, src)
            self.assertEqual(depth.shape, (2, 3))
            self.assertEqual(depth[0, 0], 0.0)
            self.assertEqual(depth[0, 2], 1001.0)
            self.assertEqual(depth[1, 0], 1500.0)
            self.assertEqual(Kr["fx"], 365.0)
            self.assertIsNone(lum)
            with open(path, "w") as f:
                f.write("1\n2\n3\n")
            with self.assertRaisesRegex(ValueError, "3 values, 3 x 2 = 6 expected"):
                sensor_io.read_frame(path, src)
            with self.assertRaisesRegex(ValueError, "unknown frame format"):
                sensor_io.read_frame(path, dict(src, format="png16"))

    def test_png_depth_frame_with_its_scale(self):
        from PIL import Image
        a = np.array([[0, 1000, 1001], [1500, 1501, 1502]], dtype=np.uint16)
        src = {"format": "png", "depth_scale": 0.5, "intrinsics": {"fx": 365.0, "fy": 365.0, "cx": 1.0, "cy": 0.5}}
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "d.png")
            Image.fromarray(a).save(path)
            depth, Kr, lum = sensor_io.read_frame(path, src)
        self.assertEqual(depth[0, 0], 0.0)
        self.assertEqual(depth[1, 2], 751.0)
        self.assertEqual(Kr["cx"], 1.0)
        self.assertIsNone(lum)


@unittest.skipIf(np is None, "numpy missing here (run under /usr/bin/python3 by NumpyElsewhere)")
class FitLosses(unittest.TestCase):
    """scripts/fit_sensors.py's time-of-flight losses."""

    def setUp(self):
        import fit_sensors
        self.fit = fit_sensors

    def test_flying_loss_weights_bins_by_real_triplets_and_skips_thin_ones(self):
        real = {"flying": {"rate": [0.9, 0.3, 0.0, None], "triplets": [50, 300, 100, 0]}}
        sim = {"flying": {"rate": [0.0, 0.2, None, 0.5]}}
        # bin 0 has 50 < 100 triplets: left out; bin 2 without a simulated rate counts as 0
        expected = (300 * 0.1 ** 2 + 100 * 0.0) / 400
        self.assertAlmostEqual(self.fit.flying_loss(sim, real, 100), expected)
        self.assertEqual(self.fit.flying_loss(sim, real, 1000), float("inf"))

    def test_held_out_frames_are_kept_apart(self):
        frames = {"frames": [{"kind": "time_of_flight", "role": "full", "local": "a"},
                             {"kind": "time_of_flight", "role": "holdout", "local": "b"},
                             {"kind": "structured_light", "role": "full", "local": "c"},
                             {"kind": "time_of_flight", "role": "geometry", "local": "d"}]}
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "sources.json")
            with open(path, "w") as f:
                json.dump(frames, f)
            fitted, held = self.fit.load_sources(path, "kinect_one")
        self.assertEqual([f["local"] for f in fitted], ["a", "d"])
        self.assertEqual([f["local"] for f in held], ["b"])

    def test_noise_loss_over_bins_with_enough_real_patches(self):
        bins = [[500.0, 750.0], [750.0, 1000.0], [1000.0, 1250.0]]
        real = {"bins_mm": bins, "noise_mm": {"median": [1.0, 1.0, 5.0], "patches": [300, 300, 50]}}
        sim = {"noise_mm": {"median": [2.0, 1.0, 1.0]}}
        # the 50-patch bin (clutter, noise 5 mm) is left out: mean of ln(2)^2 and 0
        self.assertAlmostEqual(self.fit.noise_loss_min_patches(sim, real, 200), math.log(2) ** 2 / 2)
        self.assertAlmostEqual(self.fit.noise_loss(sim, real), (math.log(2) ** 2 + math.log(5) ** 2) / 3)


@unittest.skipIf(np is not None or not os.path.exists(SYSTEM_PYTHON), "numpy importable here")
class NumpyElsewhere(unittest.TestCase):
    def test_module_passes_under_system_python(self):
        probe = subprocess.run([SYSTEM_PYTHON, "-c", "import numpy"], capture_output=True)
        if probe.returncode != 0:
            self.skipTest("no numpy under " + SYSTEM_PYTHON + " either")
        r = subprocess.run([SYSTEM_PYTHON, "-m", "unittest", "-v", "test_sensor_stats"], cwd=os.path.dirname(__file__),
                           capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)


if __name__ == "__main__":
    unittest.main()
