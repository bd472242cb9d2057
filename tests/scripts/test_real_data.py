"""scripts/real_data.py (rebuilds the real depth datasets from repository
snapshots): its pure parts on tiny inputs made here -- the PNG reader and
writer, the MAT v5 reader, the YCB-Video meta -> BOP pose conversion, the
OBJ -> PLY and models_info conversion, the test-targets builder, the GT-vs-
depth check -- and the exit code 2 with the `fetch` to run when a snapshot
is missing. Needs neither the snapshots nor the network."""
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import unittest
import zlib

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
SCRIPT = os.path.join(ROOT, "scripts", "real_data.py")
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import real_data  # noqa: E402


def png_chunk(typ, body):
    return struct.pack(">I", len(body)) + typ + body + struct.pack(">I", zlib.crc32(typ + body))


def filtered_gray16_png(w, h, values, filters):
    """A 16-bit gray PNG whose row y uses filter filters[y % len(filters)]."""
    rows = [struct.pack(">%dH" % w, *values[y * w:(y + 1) * w]) for y in range(h)]
    raw = b""
    for y, line in enumerate(rows):
        prev, f, enc = rows[y - 1] if y else bytes(len(line)), filters[y % len(filters)], bytearray()
        for i in range(len(line)):
            a, b, c = (line[i - 2], prev[i], prev[i - 2]) if i >= 2 else (0, prev[i], 0)
            pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
            paeth = a if pa <= pb and pa <= pc else b if pb <= pc else c
            enc.append((line[i] - (0, a, b, (a + b) // 2, paeth)[f]) & 255)
        raw += bytes([f]) + bytes(enc)
    return (b"\x89PNG\r\n\x1a\n" + png_chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 16, 0, 0, 0, 0))
            + png_chunk(b"IDAT", zlib.compress(raw)) + png_chunk(b"IEND", b""))


class Png(unittest.TestCase):
    VALUES = [0, 1, 255, 256, 65535, 1000, 999, 12345, 7, 0, 40000, 2]  # 4 x 3

    def test_gray16_round_trip(self):
        info, values = real_data.read_png(real_data.write_png_gray16(4, 3, self.VALUES))
        self.assertEqual((info["w"], info["h"], info["bitdepth"], info["colortype"]), (4, 3, 16, 0))
        self.assertEqual(list(values), self.VALUES)

    def test_reads_every_row_filter(self):
        values = [(37 * i * i + 11 * i) % 65536 for i in range(5 * 6)]
        info, got = real_data.read_png(filtered_gray16_png(5, 6, values, [0, 1, 2, 3, 4]))
        self.assertEqual(list(got), values)

    def test_rejects_non_png(self):
        with self.assertRaises(ValueError):
            real_data.read_png(b"GIF89a" + bytes(30))


def mat_element(typ, payload):
    return struct.pack("<II", typ, len(payload)) + payload + bytes(-len(payload) % 8)


def mat_array(name, dims, values, klass=6, dtype=9, fmt="d"):
    """A miMATRIX element; names of up to 4 characters use the small-element form."""
    name = name.encode()
    if len(name) <= 4:
        name_elem = struct.pack("<I", (len(name) << 16) | 1) + name.ljust(4, b"\0")
    else:
        name_elem = mat_element(1, name)
    return mat_element(14, mat_element(6, struct.pack("<II", klass, 0))
                       + mat_element(5, struct.pack("<%di" % len(dims), *dims)) + name_elem
                       + mat_element(dtype, struct.pack("<%d%s" % (len(values), fmt), *values)))


def compressed(element):
    """miCOMPRESSED wrapper; unlike other elements it is not padded to 8 bytes."""
    payload = zlib.compress(element)
    return struct.pack("<II", 15, len(payload)) + payload


def mat_file(*elements):
    header = b"MATLAB 5.0 MAT-file, written by test_real_data".ljust(116, b" ") + bytes(8)
    return header + struct.pack("<H", 0x0100) + b"IM" + b"".join(elements)


# Two poses in metres: identity at (0.1, 0.2, 0.9) and a turn about z at (-0.05, 0, 1.2).
POSE_A = ([1, 0, 0, 0, 1, 0, 0, 0, 1], [0.1, 0.2, 0.9])
POSE_B = ([0, -1, 0, 1, 0, 0, 0, 0, 1], [-0.05, 0.0, 1.2])


def poses_column_major(*poses):
    """MATLAB storage of a 3x4xN array [R | t] per instance."""
    out = []
    for R, t in poses:
        for c in range(4):
            out += [R[3 * r + c] if c < 3 else t[r] for r in range(3)]
    return out


class MatV5(unittest.TestCase):
    def test_reads_plain_and_compressed_arrays(self):
        poses = poses_column_major(POSE_A, POSE_B)
        cls = mat_array("cls_indexes", [2, 1], [5, 14], klass=9, dtype=2, fmt="B")  # uint8
        data = mat_file(mat_array("poses", [3, 4, 2], poses),
                        compressed(cls),
                        mat_array("fd", [1, 1], [10000], klass=6, dtype=4, fmt="H"))  # double stored as uint16
        arrays = real_data.read_mat(data)
        self.assertEqual(arrays["poses"], ([3, 4, 2], poses))
        self.assertEqual(arrays["cls_indexes"], ([2, 1], [5, 14]))
        self.assertEqual(arrays["fd"], ([1, 1], [10000]))
        self.assertEqual(real_data.mat_get(arrays["poses"], (1, 3, 0)), 0.2)  # t_y of the first pose


class MetaConversion(unittest.TestCase):
    def test_pose_is_row_major_rotation_and_millimetres(self):
        poses = ([3, 4, 2], poses_column_major(POSE_A, POSE_B))
        for k, (R, t) in enumerate((POSE_A, POSE_B)):
            gt = real_data.meta_pose(poses, k)
            self.assertEqual(gt["cam_R_m2c"], R)
            for got, want in zip(gt["cam_t_m2c"], t):
                self.assertAlmostEqual(got, want * 1000.0)

    def test_single_pose_without_third_dimension(self):
        gt = real_data.meta_pose(([3, 4], poses_column_major(POSE_B)), 0)
        self.assertEqual(gt["cam_R_m2c"], POSE_B[0])
        self.assertAlmostEqual(gt["cam_t_m2c"][2], 1200.0)

    def test_camera_k_row_major_and_depth_scale(self):
        K = [1066.778, 0.0, 0.0, 0.0, 1067.487, 0.0, 312.9869, 241.3109, 1.0]  # column-major
        cam = real_data.meta_camera({"intrinsic_matrix": ([3, 3], K), "factor_depth": ([1, 1], [10000])})
        self.assertEqual(cam["cam_K"], [1066.778, 0.0, 312.9869, 0.0, 1067.487, 241.3109, 0.0, 0.0, 1.0])
        self.assertEqual(cam["depth_scale"], 0.1)


class Targets(unittest.TestCase):
    def test_counts_instances_per_object_in_ascending_order(self):
        images = [(0, 1, [{"obj_id": 5}, {"obj_id": 2}, {"obj_id": 5}]), (0, 2, [{"obj_id": 3}, {"obj_id": 4}])]
        self.assertEqual(real_data.test_targets(images, exclude={(0, 2, 3)}), [
            {"im_id": 1, "inst_count": 1, "obj_id": 2, "scene_id": 0},
            {"im_id": 1, "inst_count": 2, "obj_id": 5, "scene_id": 0},
            {"im_id": 2, "inst_count": 1, "obj_id": 4, "scene_id": 0}])


CUBE_OBJ = "\n".join(
    ["# a cube of 20 mm, in metres"]
    + ["v %g %g %g" % (x, y, z) for x in (-0.01, 0.01) for y in (-0.01, 0.01) for z in (-0.01, 0.01)]
    + ["vn %g %g %g" % (x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    + ["vt 0 0"]
    + ["f %s" % " ".join("%d/1/%d" % (i, i) for i in face)
       for face in ((1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4))])


class Models(unittest.TestCase):
    def test_obj_to_ply_in_millimetres_with_triangles(self):
        text, V = real_data.obj_to_ply(CUBE_OBJ, "test cube")
        lines = text.splitlines()
        self.assertIn("element vertex 8", lines)
        self.assertIn("element face 12", lines)
        self.assertEqual(lines[lines.index("end_header") + 1], "-10.000000 -10.000000 -10.000000 "
                                                               "-1.000000 -1.000000 -1.000000")
        self.assertEqual(lines[-1], "3 1 7 3")  # last quad (2 6 8 4), second fan triangle, 0-based
        self.assertEqual(V[7], [10.0, 10.0, 10.0])

    def test_models_info_bbox_and_diameter(self):
        _, V = real_data.obj_to_ply(CUBE_OBJ, "test cube")
        info = real_data.models_info_entry(V, real_data.diameter_directions())
        self.assertEqual((info["min_x"], info["min_y"], info["min_z"]), (-10.0, -10.0, -10.0))
        self.assertEqual((info["size_x"], info["size_y"], info["size_z"]), (20.0, 20.0, 20.0))
        self.assertAlmostEqual(info["diameter"], 20.0 * 3 ** 0.5, places=4)

    def test_ply_reader_reads_back_points_and_normals(self):
        text, V = real_data.obj_to_ply(CUBE_OBJ, "test cube")
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "cube.ply")
            with open(path, "w") as f:
                f.write(text)
            points, normals = real_data.read_ply_points(path)
        self.assertEqual([list(p) for p in points], V)
        self.assertEqual(normals[0], (-1.0, -1.0, -1.0))


class GtCheck(unittest.TestCase):
    # A 41 x 41 grid of points 1 mm apart facing the camera, 1 m in front of it.
    GRID = [(x, y, 0.0) for x in range(-20, 21) for y in range(-20, 21)]
    NORMALS = [(0.0, 0.0, -1.0)] * len(GRID)
    GT = {"cam_R_m2c": [1, 0, 0, 0, 1, 0, 0, 0, 1], "cam_t_m2c": [0.0, 0.0, 1000.0]}
    CAM = {"cam_K": [500.0, 0.0, 32.0, 0.0, 500.0, 24.0, 0.0, 0.0, 1.0], "depth_scale": 0.1}

    def check(self, depth_mm, normals=NORMALS):
        depth = [int(depth_mm / 0.1)] * (64 * 48)
        return real_data.check_instance(self.GRID, normals, self.GT, self.CAM, depth, 64, 48, step=1)

    def test_depth_on_the_surface_is_all_inliers(self):
        n, inliers, median = self.check(1000.0)
        self.assertEqual((n, inliers), (len(self.GRID), 1.0))
        self.assertAlmostEqual(median, 0.0)

    def test_depth_12mm_behind_is_no_inlier(self):
        n, inliers, median = self.check(1012.0)
        self.assertEqual(inliers, 0.0)
        self.assertAlmostEqual(median, 12.0)

    def test_occluded_and_back_facing_points_are_not_counted(self):
        self.assertEqual(self.check(900.0), (0, None, None))  # 100 mm in front: occluder
        self.assertEqual(self.check(1000.0, [(0.0, 0.0, 1.0)] * len(self.GRID)), (0, None, None))


class MissingMirrors(unittest.TestCase):
    def run_script(self, mirrors, only):
        with tempfile.TemporaryDirectory() as out:
            return subprocess.run([sys.executable, SCRIPT, "--mirrors", mirrors, "--out", out, "--only", only],
                                  capture_output=True, text=True, timeout=60)

    def test_missing_mirror_exits_2_naming_repository_commit_and_fetch(self):
        with tempfile.TemporaryDirectory() as mirrors:
            r = self.run_script(mirrors, "lmo")
        self.assertEqual(r.returncode, 2, r.stderr)
        for repo in ("yufu-wang/6D_Pose", "JiehongLin/SAM-6D"):
            self.assertIn("%s @ %s" % (repo, real_data.COMMITS[repo]), r.stderr)
            self.assertIn("fetch github:%s" % repo, r.stderr)
        self.assertNotIn("oprb/ycbvideo", r.stderr)  # not needed for lmo

    @unittest.skipIf(shutil.which("git") is None, "git missing")
    def test_mirror_without_the_commit_exits_2(self):
        with tempfile.TemporaryDirectory() as mirrors:
            for repo in real_data.NEEDS["ycbv"]:
                subprocess.run(["git", "init", "-q", "--bare", os.path.join(mirrors, repo.replace("/", "+"), "repo")],
                               check=True)
            r = self.run_script(mirrors, "ycbv")
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("oprb/ycbvideo @ %s" % real_data.COMMITS["oprb/ycbvideo"], r.stderr)
        self.assertIn("holding the commit", r.stderr)

    def test_unknown_dataset_is_a_usage_error(self):
        with tempfile.TemporaryDirectory() as mirrors:
            r = self.run_script(mirrors, "tless")
        self.assertEqual(r.returncode, 2)
        self.assertIn("unknown dataset", r.stderr)


class Provenance(unittest.TestCase):
    def test_every_written_file_records_repo_commit_and_path(self):
        prov = {}
        with tempfile.TemporaryDirectory() as d:
            out = real_data.Output(d, "lmo", prov)
            out.write_json("test/000002/scene_gt.json", {"3": []}, [("yufu-wang/6D_Pose", "a/b.json")], "restricted")
            with open(os.path.join(d, "lmo", "test", "000002", "scene_gt.json")) as f:
                self.assertEqual(json.load(f), {"3": []})
        self.assertEqual(prov["lmo/test/000002/scene_gt.json"]["sources"], [
            {"repo": "yufu-wang/6D_Pose", "commit": real_data.COMMITS["yufu-wang/6D_Pose"], "path": "a/b.json"}])


if __name__ == "__main__":
    unittest.main()
