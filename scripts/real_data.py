#!/usr/bin/env python3
"""Rebuilds the real depth datasets with ground-truth poses used by posebench
(BOP layout) from local git snapshots of the public repositories holding them:

    python3 scripts/real_data.py --mirrors DIR --out OUT
        [--only lmo,ycbv,graspnet_kinect] [--check]

Why: the sim-to-real comparisons need real sensor depth with known object
poses, but the project never commits that data; this recreates it exactly.
DIR holds DIR/OWNER+NAME/repo git directories (what `fetch github:OWNER/NAME`
writes); every file is `git show COMMIT:PATH` at the pinned COMMITS below.
Written under OUT:

  lmo/              LM-O scene 2 image 3 (Kinect v1 structured light, mm)
  ycbv/             101 YCB-Video frames of videos 0-3, 49, 50 (Asus Xtion,
                    0.1 mm), meshes converted from the YCB-Video OBJs
  graspnet_kinect/  GraspNet-1Billion scene 0, images 16 and 135 (Azure Kinect
                    time-of-flight, mm); cracker box and banana annotated only
  PROVENANCE.json   for every written file: repository, commit, path(s)

Each dataset: camera.json, models/ (obj_XXXXXX.ply in mm, models_info.json),
test/SCENE/{scene_camera,scene_gt[,scene_gt_info]}.json with depth/ and rgb/,
test_targets_bop19.json. --check prints per GT instance the fraction of
camera-facing model vertices within 10 mm of the measured depth (inlier10)
and the median depth error. Standard library only (own PNG and MAT v5
readers). Exit code 2 if a mirror or commit is missing."""
import argparse
import collections
import json
import math
import os
import random
import struct
import subprocess
import sys
import zlib

# Repository -> the commit the data was taken from (recorded with the data).
COMMITS = {
    "yufu-wang/6D_Pose": "1ae3421dcdecd95da6f203eed8004f3c33df62a2",  # LM-O BOP files
    "JiehongLin/SAM-6D": "1c2543b3b6faa1f1d81b3c7291f8b371d71e50c2",  # LM-O depth of scene 2 im 3
    "carlocolizzi/YCB-Video_Augmented_Dataset": "e1050ed0e54573a2ccbec00a4f5153ecbf455d2b",  # frames, meshes
    "oprb/ycbvideo": "31513757cb1d23cc40c8ec924ed6d2c6a9655a61",  # YCB-Video frame 0003/000138
    "GouMinghao/simple_grasp": "e7af6dfb362da1ddfc328375c3970eb48851e13d",  # GraspNet-1Billion sample
}
LMO_REPO, SAM6D_REPO, YCB_REPO, OPRB_REPO, GRASP_REPO = COMMITS
NEEDS = {"lmo": [LMO_REPO, SAM6D_REPO], "ycbv": [YCB_REPO, OPRB_REPO],
         "graspnet_kinect": [GRASP_REPO, YCB_REPO]}  # graspnet reuses two YCB-Video meshes

LMO_OBJECTS = (1, 5, 6, 8, 9, 10, 11, 12)
# YCB-Video class order = BOP ycbv object ids 1..21.
YCB_CLASSES = ("002_master_chef_can", "003_cracker_box", "004_sugar_box", "005_tomato_soup_can",
               "006_mustard_bottle", "007_tuna_fish_can", "008_pudding_box", "009_gelatin_box",
               "010_potted_meat_can", "011_banana", "019_pitcher_base", "021_bleach_cleanser", "024_bowl",
               "025_mug", "035_power_drill", "036_wood_block", "037_scissors", "040_large_marker",
               "051_large_clamp", "052_extra_large_clamp", "061_foam_brick")
# (repo, folder, video, frame numbers); BOP scene id = video id, image id = frame number.
YCB_FRAMES = [(YCB_REPO, "Example-Scenes/%04d" % v, v, range(1, 21)) for v in (0, 1, 2, 49, 50)]
YCB_FRAMES.append((OPRB_REPO, "data/tests/ycb_video_dataset/special_data/0003", 3, [138]))
GRASP_DIR = "data/graspnet_sample/scenes/scene_0000/kinect"
GRASP_IMAGES = (16, 135)
GRASP_TO_YCB = {1: 2, 6: 10}  # GraspNet cls_index -> YCB-Video object id (cracker box, banana)
# GT instances left out of test_targets_bop19.json (kept in scene_gt.json):
TARGET_EXCLUDE = {
    "ycbv": {(3, 138, 14)},             # the mug projects entirely outside the image
    "graspnet_kinect": {(0, 135, 10)},  # Kinect depth lies ~15 mm behind this banana's GT
}


class MirrorError(Exception):
    """A repository snapshot, commit or file that the build needs is missing."""


# ---------------------------------------------------------------- git mirrors
def git_dir(mirrors, repo):
    """DIR/OWNER+NAME/repo, or its .git when the snapshot has a work tree."""
    d = os.path.join(mirrors, repo.replace("/", "+"), "repo")
    return os.path.join(d, ".git") if os.path.isdir(os.path.join(d, ".git")) else d


def missing_mirrors(mirrors, repos):
    """One message per repository whose snapshot or pinned commit is absent."""
    problems = []
    for repo in repos:
        commit, d = COMMITS[repo], git_dir(mirrors, repo)
        if not os.path.isdir(d):
            why = "no mirror at %s" % d
        elif subprocess.run(["git", "--git-dir", d, "cat-file", "-e", commit + "^{commit}"],
                            capture_output=True).returncode != 0:
            why = "%s is no git directory holding the commit" % d
        else:
            continue
        problems.append("%s @ %s: %s; run: fetch github:%s" % (repo, commit, why, repo))
    return problems


def show(mirrors, repo, path):
    """The bytes of PATH at the pinned commit of REPO."""
    r = subprocess.run(["git", "--git-dir", git_dir(mirrors, repo), "show", "%s:%s" % (COMMITS[repo], path)],
                       capture_output=True)
    if r.returncode != 0:
        raise MirrorError("%s @ %s: cannot read %s: %s" % (repo, COMMITS[repo], path, r.stderr.decode().strip()))
    return r.stdout


# ------------------------------------------------------------------------ PNG
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png_chunks(data):
    """(type, body) of every chunk of a PNG file."""
    if data[:8] != PNG_SIGNATURE:
        raise ValueError("not a PNG file")
    pos = 8
    while pos + 8 <= len(data):
        (n,) = struct.unpack(">I", data[pos:pos + 4])
        yield data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        pos += 12 + n


def unfilter_row(ftype, line, prev, bpp):
    """Undo one PNG row filter (0 none, 1 sub, 2 up, 3 average, 4 Paeth) in place."""
    for i in range(len(line) if ftype else 0):
        a, b, c = (line[i - bpp], prev[i], prev[i - bpp]) if i >= bpp else (0, prev[i], 0)
        if ftype == 4:
            pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
            line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        else:
            line[i] = (line[i] + (0, a, b, (a + b) // 2)[ftype]) & 255


def read_png(data):
    """({w, h, bitdepth, colortype}, pixels) of a non-interlaced PNG; pixels is a
    tuple of ints for 16-bit gray (depth maps), else the raw unfiltered bytes."""
    chunks = list(png_chunks(data))
    w, h, bd, ct, _, _, interlace = struct.unpack(">IIBBBBB", chunks[0][1])
    if interlace:
        raise ValueError("interlaced PNG not supported")
    channels = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}[ct]
    bpp, stride = max(1, channels * bd // 8), (w * channels * bd + 7) // 8
    raw = zlib.decompress(b"".join(body for typ, body in chunks if typ == b"IDAT"))
    out, prev = bytearray(), bytearray(stride)
    for y in range(h):
        row = y * (stride + 1)
        line = bytearray(raw[row + 1:row + 1 + stride])
        unfilter_row(raw[row], line, prev, bpp)
        out += line
        prev = line
    info = {"w": w, "h": h, "bitdepth": bd, "colortype": ct}
    if bd == 16 and ct == 0:
        return info, struct.unpack(">%dH" % (w * h), bytes(out))
    return info, bytes(out)


def write_png_gray16(w, h, values):
    """A 16-bit grayscale PNG (unfiltered rows) of w*h row-major values."""
    def chunk(typ, body):
        return struct.pack(">I", len(body)) + typ + body + struct.pack(">I", zlib.crc32(typ + body))
    rows = b"".join(b"\0" + struct.pack(">%dH" % w, *values[y * w:(y + 1) * w]) for y in range(h))
    return (PNG_SIGNATURE + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 16, 0, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


# --------------------------------------------------------------------- MAT v5
MAT_TYPES = {1: "b", 2: "B", 3: "h", 4: "H", 5: "i", 6: "I", 7: "f", 9: "d", 12: "q", 13: "Q"}
NUMERIC_CLASSES = range(6, 16)  # double, single, int8 .. uint64


def mat_elements(buf, endian):
    """(type, data) of the data elements in buf, small (packed) ones included."""
    pos, out = 0, []
    while pos + 8 <= len(buf):
        typ, n = struct.unpack(endian + "II", buf[pos:pos + 8])
        if typ >> 16:  # small element: size in the upper half, data in the tag's second word
            n, typ = typ >> 16, typ & 0xFFFF
            out.append((typ, buf[pos + 4:pos + 4 + n]))
            pos += 8
            continue
        out.append((typ, buf[pos + 8:pos + 8 + n]))
        pos += 8 + n
        if typ != 15:  # compressed elements are not padded to 8 bytes
            pos = (pos + 7) // 8 * 8
    return out


def mat_numbers(typ, data, endian):
    fmt = MAT_TYPES[typ]
    return list(struct.unpack(endian + fmt * (len(data) // struct.calcsize(fmt)), data))


def read_mat(data):
    """{name: (dims, column-major values)} of the numeric arrays of a MAT v5 file
    (values None for cells, structs and other classes)."""
    endian = "<" if data[126:128] == b"IM" else ">"
    arrays = {}
    for typ, body in mat_elements(data[128:], endian):
        if typ == 15:  # miCOMPRESSED: one zlib-compressed element
            typ, body = mat_elements(zlib.decompress(body), endian)[0]
        if typ != 14:  # not miMATRIX
            continue
        parts = mat_elements(body, endian)
        klass = mat_numbers(*parts[0], endian)[0] & 0xFF
        dims, name = mat_numbers(*parts[1], endian), parts[2][1].decode()
        arrays[name] = (dims, mat_numbers(*parts[3], endian) if klass in NUMERIC_CLASSES else None)
    return arrays


def mat_get(array, index):
    """Element of a column-major array at index (missing trailing indices are 0)."""
    dims, values = array
    offset, stride = 0, 1
    for i, d in zip(index, dims):
        offset, stride = offset + i * stride, stride * d
    return values[offset]


# ---------------------------------------------------------------- conversions
def meta_pose(poses, k):
    """BOP pose of instance k of a YCB-Video/GraspNet meta `poses` (3x4xN, metres):
    cam_R_m2c = poses[:, :3, k] row-major, cam_t_m2c = poses[:, 3, k] in mm."""
    if len(poses[0]) == 2:  # MATLAB drops the trailing 1 of a single 3x4 pose
        poses = (poses[0] + [1], poses[1])
    return {"cam_R_m2c": [mat_get(poses, (r, c, k)) for r in range(3) for c in range(3)],
            "cam_t_m2c": [mat_get(poses, (r, 3, k)) * 1000.0 for r in range(3)]}


def meta_camera(meta):
    """BOP scene_camera entry: K row-major, depth_scale = mm per depth unit."""
    K = meta["intrinsic_matrix"]
    return {"cam_K": [mat_get(K, (r, c)) for r in range(3) for c in range(3)],
            "depth_scale": 1000.0 / meta["factor_depth"][1][0]}


def test_targets(images, exclude=()):
    """BOP test_targets_bop19 list: for each (scene, im, gts) and each object id
    (ascending), its instance count; (scene, im, obj) in exclude are left out."""
    targets = []
    for scene, im, gts in images:
        counts = collections.Counter(g["obj_id"] for g in gts)
        targets += [{"im_id": im, "inst_count": n, "obj_id": o, "scene_id": scene}
                    for o, n in sorted(counts.items()) if (scene, im, o) not in exclude]
    return targets


def obj_to_ply(obj_text, comment):
    """(ASCII PLY text in mm, vertices in mm) of a Wavefront OBJ in metres with one
    normal per vertex; polygons are fan-triangulated, texture coordinates dropped."""
    V, N, F = [], [], []
    for line in obj_text.splitlines():
        p = line.split()
        if p and p[0] == "v":
            V.append([float(x) * 1000.0 for x in p[1:4]])
        elif p and p[0] == "vn":
            N.append([float(x) for x in p[1:4]])
        elif p and p[0] == "f":
            idx = [int(q.split("/")[0]) - 1 for q in p[1:]]
            F += [(idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1)]
    if len(N) != len(V):
        raise ValueError("expected one normal per vertex")
    head = ["ply", "format ascii 1.0", "comment " + comment, "element vertex %d" % len(V)]
    head += ["property float %s" % a for a in ("x", "y", "z", "nx", "ny", "nz")]
    head += ["element face %d" % len(F), "property list uchar int vertex_indices", "end_header"]
    body = ["%.6f %.6f %.6f %.6f %.6f %.6f" % (*v, *n) for v, n in zip(V, N)]
    body += ["3 %d %d %d" % f for f in F]
    return "\n".join(head + body) + "\n", V


def diameter_directions(n=400, seed=0):
    """Fixed pseudo-random unit directions (seeded: the diameters must be reproducible)."""
    rng, dirs = random.Random(seed), []
    for _ in range(n):
        v = [rng.gauss(0, 1) for _ in range(3)]
        norm = math.sqrt(sum(x * x for x in v))
        dirs.append([x / norm for x in v])
    return dirs


def models_info_entry(V, dirs):
    """BOP models_info entry: bbox, and diameter as the largest distance among the
    extreme vertices along dirs (a close lower bound of the true diameter)."""
    lo = [min(v[k] for v in V) for k in range(3)]
    hi = [max(v[k] for v in V) for k in range(3)]
    extremes = set()
    for d in dirs:
        proj = [v[0] * d[0] + v[1] * d[1] + v[2] * d[2] for v in V]
        extremes.update((proj.index(max(proj)), proj.index(min(proj))))
    pts = [V[j] for j in extremes]
    diam2 = max((sum((a[k] - b[k]) ** 2 for k in range(3)) for i, a in enumerate(pts) for b in pts[i + 1:]),
                default=0.0)
    return {"diameter": round(math.sqrt(diam2), 4), "min_x": lo[0], "min_y": lo[1], "min_z": lo[2],
            "size_x": hi[0] - lo[0], "size_y": hi[1] - lo[1], "size_z": hi[2] - lo[2]}


# ------------------------------------------------------ output and provenance
class Output:
    """Writes files under one dataset directory and records where each came from."""

    def __init__(self, root, name, provenance):
        self.root, self.name, self.provenance = root, name, provenance

    def write(self, rel, data, sources, conversion="byte copy"):
        path = os.path.join(self.root, self.name, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "wb") as f:
            f.write(data if isinstance(data, bytes) else data.encode())
        self.provenance["%s/%s" % (self.name, rel)] = {
            "sources": [{"repo": r, "commit": COMMITS[r], "path": p} for r, p in sources],
            "conversion": conversion}

    def write_json(self, rel, obj, sources, conversion):
        self.write(rel, json.dumps(obj, indent=2), sources, conversion)


# ------------------------------------------------------------------- builders
def build_lmo(mirrors, out):
    """LM-O: the BOP files of scene 2 restricted to image 3, the one image whose
    depth map is public (SAM-6D's example depth.png; its rgb.png is the same blob
    as LM-O test/000002/rgb/000003.png)."""
    base = "data/bop/lmo/"
    def copy(rel):
        out.write(rel, show(mirrors, LMO_REPO, base + rel), [(LMO_REPO, base + rel)])
    copy("camera.json")
    copy("models/models_info.json")
    for o in LMO_OBJECTS:
        copy("models/obj_%06d.ply" % o)
    for name in ("scene_camera", "scene_gt", "scene_gt_info"):
        rel = "test/000002/%s.json" % name
        full = json.loads(show(mirrors, LMO_REPO, base + rel))
        out.write_json(rel, {"3": full["3"]}, [(LMO_REPO, base + rel)], "restricted to image 3")
    targets = [t for t in json.loads(show(mirrors, LMO_REPO, base + "test_targets_bop19.json"))
               if (t["scene_id"], t["im_id"]) == (2, 3)]
    out.write_json("test_targets_bop19.json", targets, [(LMO_REPO, base + "test_targets_bop19.json")],
                   "restricted to scene 2 image 3")
    copy("test/000002/rgb/000003.png")
    out.write("test/000002/depth/000003.png", show(mirrors, SAM6D_REPO, "SAM-6D/Data/Example/depth.png"),
              [(SAM6D_REPO, "SAM-6D/Data/Example/depth.png")])


def build_ycb_models(mirrors, out, obj_ids, dirs):
    """models/obj_XXXXXX.ply and models_info.json from YCB-Video textured_simple.obj."""
    info = {}
    for o in obj_ids:
        src = "models/%s/textured_simple.obj" % YCB_CLASSES[o - 1]
        text, V = obj_to_ply(show(mirrors, YCB_REPO, src).decode(),
                             "units: mm; converted from YCB-Video %s (meters x1000)" % src)
        out.write("models/obj_%06d.ply" % o, text, [(YCB_REPO, src)], "OBJ (m) -> ASCII PLY (mm), normals kept")
        info[str(o)] = models_info_entry(V, dirs)
    out.write_json("models/models_info.json", info,
                   [(YCB_REPO, "models/%s/textured_simple.obj" % YCB_CLASSES[o - 1]) for o in obj_ids],
                   "bbox and diameter (extremes along 400 seeded directions) computed from the meshes")


def convert_frame(mirrors, out, repo, scene, im, paths, obj_id):
    """Copies one frame's depth and rgb PNGs and converts its meta.mat. paths:
    (meta, depth, rgb); obj_id: class index -> object id, or None to skip it."""
    meta_path, depth_path, rgb_path = paths
    meta = read_mat(show(mirrors, repo, meta_path))
    gt = [dict(meta_pose(meta["poses"], k), obj_id=obj_id(int(c)))
          for k, c in enumerate(meta["cls_indexes"][1]) if obj_id(int(c)) is not None]
    depth = show(mirrors, repo, depth_path)
    out.write("test/%06d/depth/%06d.png" % (scene, im), depth, [(repo, depth_path)])
    out.write("test/%06d/rgb/%06d.png" % (scene, im), show(mirrors, repo, rgb_path), [(repo, rgb_path)])
    return {"scene": scene, "im": im, "gt": gt, "cam": meta_camera(meta), "meta": (repo, meta_path),
            "depth": depth}


def write_gt(out, frames, exclude):
    """Per scene scene_gt.json and scene_camera.json (images ascending), then
    camera.json (all frames must share one camera) and test_targets_bop19.json."""
    scenes, metas = {}, [f["meta"] for f in frames]
    for f in frames:
        scenes.setdefault(f["scene"], []).append(f)
    for scene, fs in scenes.items():
        fs, rel = sorted(fs, key=lambda f: f["im"]), "test/%06d/" % scene
        out.write_json(rel + "scene_gt.json", {str(f["im"]): f["gt"] for f in fs}, [f["meta"] for f in fs],
                       "meta.mat poses (3x4, m) -> cam_R_m2c row-major, cam_t_m2c mm")
        out.write_json(rel + "scene_camera.json", {str(f["im"]): f["cam"] for f in fs}, [f["meta"] for f in fs],
                       "meta.mat intrinsic_matrix -> cam_K, depth_scale = 1000 / factor_depth")
    cams = [f["cam"] for f in frames]
    if any(c != cams[0] for c in cams):
        raise ValueError("the frames of %s disagree on the camera" % out.name)
    K, (w, h) = cams[0]["cam_K"], struct.unpack(">II", next(png_chunks(frames[0]["depth"]))[1][:8])
    out.write_json("camera.json", {"cx": K[2], "cy": K[5], "depth_scale": cams[0]["depth_scale"], "fx": K[0],
                                   "fy": K[4], "height": h, "width": w},
                   metas, "the single K of all meta.mat, the size of the depth PNGs")
    out.write_json("test_targets_bop19.json", test_targets([(f["scene"], f["im"], f["gt"]) for f in frames],
                                                           exclude),
                   metas, "every GT instance, counted per object, minus TARGET_EXCLUDE")


def build_ycbv(mirrors, out, dirs):
    """YCB-Video frames NNNN/XXXXXX-{depth,color}.png + -meta.mat -> BOP scene
    NNNN, image XXXXXX; all 21 meshes."""
    frames = []
    for repo, folder, scene, ims in YCB_FRAMES:
        for im in ims:
            pre = "%s/%06d-" % (folder, im)
            frames.append(convert_frame(mirrors, out, repo, scene, im,
                                        (pre + "meta.mat", pre + "depth.png", pre + "color.png"), lambda c: c))
    write_gt(out, frames, TARGET_EXCLUDE["ycbv"])
    build_ycb_models(mirrors, out, range(1, len(YCB_CLASSES) + 1), dirs)


def build_graspnet(mirrors, out, dirs):
    """GraspNet-1Billion scene_0000, camera kinect, two views: GT of the objects
    with YCB-Video meshes only (the other seven are unannotated clutter)."""
    frames = [convert_frame(mirrors, out, GRASP_REPO, 0, im,
                            ["%s/%s/%04d.%s" % (GRASP_DIR, kind, im, ext)
                             for kind, ext in (("meta", "mat"), ("depth", "png"), ("rgb", "png"))],
                            GRASP_TO_YCB.get) for im in GRASP_IMAGES]
    write_gt(out, frames, TARGET_EXCLUDE["graspnet_kinect"])
    build_ycb_models(mirrors, out, sorted(GRASP_TO_YCB.values()), dirs)


BUILDERS = {"lmo": lambda m, o, d: build_lmo(m, o), "ycbv": build_ycbv, "graspnet_kinect": build_graspnet}


# ---------------------------------------------------------------- GT check
def read_ply_points(path):
    """Vertices and (possibly empty) normals of an ASCII PLY."""
    with open(path) as f:
        props, n, element = [], 0, None
        for line in f:
            p = line.split()
            if p[:1] == ["format"] and p[1] != "ascii":
                raise ValueError("%s: only ASCII PLY is supported" % path)
            if p[:1] == ["element"]:
                element, n = p[1], (int(p[2]) if p[1] == "vertex" else n)
            elif p[:1] == ["property"] and element == "vertex":
                props.append(p[-1])
            elif p == ["end_header"]:
                break
        rows = [[float(x) for x in next(f).split()] for _ in range(n)]
    col = props.index
    V = [(r[col("x")], r[col("y")], r[col("z")]) for r in rows]
    N = [(r[col("nx")], r[col("ny")], r[col("nz")]) for r in rows] if "nx" in props else []
    return V, N


def check_instance(V, N, gt, cam, depth, w, h, step=3):
    """(visible points, inlier10, median depth error mm) of one GT instance: every
    step-th camera-facing vertex inside the image with valid depth, not occluded
    (measured depth more than 15 mm in front of it)."""
    R, t, K, s = gt["cam_R_m2c"], gt["cam_t_m2c"], cam["cam_K"], cam["depth_scale"]
    errors = []
    for j in range(0, len(V), step):
        X, Y, Z = (R[3 * r] * V[j][0] + R[3 * r + 1] * V[j][1] + R[3 * r + 2] * V[j][2] + t[r] for r in range(3))
        if N and sum((R[3 * r] * N[j][0] + R[3 * r + 1] * N[j][1] + R[3 * r + 2] * N[j][2]) * P
                     for r, P in enumerate((X, Y, Z))) >= 0:
            continue  # faces away from the camera
        u, v = int(K[0] * X / Z + K[2] + 0.5), int(K[4] * Y / Z + K[5] + 0.5)
        if not (0 <= u < w and 0 <= v < h) or depth[v * w + u] == 0:
            continue
        d = depth[v * w + u] * s
        if d >= Z - 15:
            errors.append(d - Z)
    if not errors:
        return 0, None, None
    errors.sort()
    return len(errors), sum(abs(e) < 10 for e in errors) / len(errors), errors[len(errors) // 2]


def read_json(path):
    with open(path) as f:
        return json.load(f)


def check_dataset(root):
    """Prints the GT-vs-depth check of every instance of a built dataset."""
    models = {}
    for scene in sorted(os.listdir(os.path.join(root, "test"))):
        sd = os.path.join(root, "test", scene)
        gts, cams = (read_json(os.path.join(sd, "scene_%s.json" % n)) for n in ("gt", "camera"))
        for im in gts:
            with open(os.path.join(sd, "depth", "%06d.png" % int(im)), "rb") as f:
                info, depth = read_png(f.read())
            for gt in gts[im]:
                o = gt["obj_id"]
                if o not in models:
                    models[o] = read_ply_points(os.path.join(root, "models", "obj_%06d.ply" % o))
                n, inl, med = check_instance(*models[o], gt, cams[im], depth, info["w"], info["h"])
                print("%s scene %d im %d obj %d: visible %d inlier10 %s med_err %s mm"
                      % (os.path.basename(root), int(scene), int(im), o, n,
                         "n/a" if inl is None else "%.3f" % inl, "n/a" if med is None else "%.1f" % med))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mirrors", required=True, help="directory of OWNER+NAME/repo git snapshots")
    ap.add_argument("--out", required=True)
    ap.add_argument("--only", default=",".join(BUILDERS), help="comma-separated datasets (default: all)")
    ap.add_argument("--check", action="store_true", help="print the GT-vs-depth check per instance")
    args = ap.parse_args(argv)
    names = [n for n in args.only.split(",") if n]
    unknown = [n for n in names if n not in BUILDERS]
    if unknown:
        ap.error("unknown dataset(s): %s (choose from %s)" % (", ".join(unknown), ", ".join(BUILDERS)))
    repos = sorted({r for n in names for r in NEEDS[n]})
    problems = missing_mirrors(args.mirrors, repos)
    if problems:
        print("real_data.py: missing repository snapshots:\n  " + "\n  ".join(problems), file=sys.stderr)
        return 2
    provenance, dirs = {}, diameter_directions()
    try:
        for name in names:
            BUILDERS[name](args.mirrors, Output(args.out, name, provenance), dirs)
            print("built %s" % os.path.join(args.out, name))
    except MirrorError as e:
        print("real_data.py: %s" % e, file=sys.stderr)
        return 2
    with open(os.path.join(args.out, "PROVENANCE.json"), "w") as f:
        json.dump({"generated_by": "scripts/real_data.py", "repositories": {r: COMMITS[r] for r in repos},
                   "files": provenance}, f, indent=2, sort_keys=True)
    for name in names if args.check else []:
        check_dataset(os.path.join(args.out, name))
    return 0


if __name__ == "__main__":
    sys.exit(main())
