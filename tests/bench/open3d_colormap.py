#!/usr/bin/python3
"""Open3D's ColorMap baseline, scored with `fresco rephoto`'s virtual rephotography.

A benchmark, not a test: an independent yardstick for Fresco's painting. For each frame that
`fresco rephoto PROJECT.json --every N` leaves out (the first frame with a pose and every N-th
after it, in the order Fresco reads them), Open3D's colour map
(`o3d.pipelines.color_map.run_rigid_optimizer` with `maximum_iteration=0`: no pose
optimisation, every vertex the plain average of the views that see it) colours the project's
mesh from all the OTHER posed frames; the vertex-coloured mesh is rendered at the left-out pose
and compared with the photo by Fresco's own metrics (pipeline/core/image_metrics.cc, re-coded
here): PSNR over the compared pixels and local 1-NCC (9 x 9 boxes, mask eroded by 9 x 9).
The compared pixels follow Fresco's rule (pipeline/paint/rephotography.cc): the surface is seen
and painted, here: the pixel's triangle has all three vertices coloured by some view.

Run with Debian's python (python3-open3d 0.16, numpy, OpenCV):

  /usr/bin/python3 tests/bench/open3d_colormap.py PROJECT.json --out DIR [--every N]
      [--fresco-out REPHOTO_DIR] [--renderer auto|fresco|numpy] [--depth auto|render|capture]
      [--views] [--fresco BIN]

  --every N        as `fresco rephoto --every N` (default 1)
  --fresco-out D   a `fresco rephoto` output folder of the same project and --every: checks
                   the metrics re-coded here against Fresco's (rephoto.json beside the render
                   and photo of views/NAME.png) and scores Open3D and Fresco on the pixels
                   both painted
  --renderer R     who decides which triangle each pixel sees: `fresco` (`fresco render
                   --ids`, Fresco's own rasterizer; vertex colours are then interpolated here
                   with exact ray/triangle barycentrics), `numpy` (a z-buffer here), `auto`
                   (fresco when the binary exists). Open3D's RaycastingScene is not used:
                   Debian's Open3D 0.16 with Debian's Embree 3.13 finds no hits at all
  --depth D        the depth Open3D's visibility test reads: `render` (the mesh's depth at each
                   pose), `capture` (a TUM RGB-D capture's registered depth: the video folder
                   is .../rgb with .../depth beside it, paired by frames.txt or by time;
                   --depth-scale 5000), `auto` (capture when that layout is there)
  --views          also write DIR/views/NAME.png: Open3D's render beside the photo
  --self-check     check the metrics re-coded here against their definitions, slowly, on
                   random images, and exit

Open3D's RigidOptimizerOption keeps its defaults (visibility 0.03, discontinuity 0.1, dilation 3,
margin 10) but for two: maximum_allowable_depth is off (2.5 would drop any scene farther than
that), and invisible_vertex_color_knn is 0 (unseen vertices stay unpainted and are not scored,
as Fresco's unpainted texels). --o3d-scale F multiplies the distance thresholds (they are
metres for a Kinect at about 1 m); --sample-shift 0.5 adds half a pixel to the cx, cy Open3D
gets (its colour lookup truncates u, v instead of rounding them); --frames K scores only the
first K cases (a quick look).

Writes DIR/open3d_colormap.json and DIR/open3d_colormap.md (also printed). Open3D runs with its
default threads; its CPU seconds (process time over the call, all threads) are given per frame.
Cameras: COLMAP PINHOLE / SIMPLE_PINHOLE (cx, cy shifted by -0.5 as Fresco reads them), a
COLMAP model whose distortion is all zero, or an mrcal LENSMODEL_PINHOLE .cameramodel; any
other lens is refused (Open3D's colour map knows only pinholes: undistort the frames first).
Poses: COLMAP images.txt (or its folder) or a TUM trajectory, as Fresco matches them to frames.
"""

import argparse
import ast
import json
import math
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import cv2
import numpy as np
import open3d as o3d

IMAGE_EXTENSIONS = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".ppm"}
COLMAP_PIXEL_SHIFT = 0.5  # COLMAP's pixel centre minus Fresco's (docs/reference/file-formats.md)
MIN_TRIANGLE_AREA = 1e-14  # SceneLoadOptions::min_triangle_area_m2: smaller ones Fresco drops


class Refused(Exception):
    """Input this benchmark cannot score: the message says why."""


# ---------------------------------------------------------------------------------------------
# Fresco's metrics (pipeline/core/image_metrics.cc), line for line.


def psnr_db(a, b, mask):
    """PsnrDb: 8-bit peak, over the mask's pixels and every channel; NaN for an empty mask."""
    m = mask != 0
    n = int(m.sum()) * (a.shape[2] if a.ndim == 3 else 1)
    if n == 0:
        return float("nan")
    d = a[m].astype(np.float64) - b[m].astype(np.float64)
    mse = float((d * d).sum()) / n
    if mse == 0.0:
        return float("inf")
    return 10.0 * math.log10(255.0 * 255.0 / mse)


def local_one_minus_ncc(a, b, mask, window=9):
    """LocalOneMinusNcc: 1 - NCC of the grey values in every window x window box, averaged
    over the pixels whose whole box is in the mask (OpenCV's default borders, as in C++)."""
    ga = cv2.cvtColor(a, cv2.COLOR_BGR2GRAY) if a.ndim == 3 else a
    gb = cv2.cvtColor(b, cv2.COLOR_BGR2GRAY) if b.ndim == 3 else b
    fa, fb = ga.astype(np.float64), gb.astype(np.float64)
    box = (window, window)
    ma, mb = cv2.blur(fa, box), cv2.blur(fb, box)
    maa, mbb, mab = cv2.blur(fa * fa, box), cv2.blur(fb * fb, box), cv2.blur(fa * fb, box)
    inside = cv2.erode((mask != 0).astype(np.uint8) * 255, np.ones((window, window), np.uint8))
    m = inside != 0
    if not m.any():
        return float("nan")
    va = maa[m] - ma[m] * ma[m]
    vb = mbb[m] - mb[m] * mb[m]
    cov = mab[m] - ma[m] * mb[m]
    return float(np.mean(1.0 - cov / np.sqrt(np.maximum(va * vb, 1e-6))))


def score(photo_bgr, rendered_bgr, compared, surface_pixels):
    """ScoreRephoto's figures for a render (black outside `compared`) against the photo."""
    pixels = int(np.count_nonzero(compared))
    rendered = rendered_bgr.copy()
    rendered[compared == 0] = 0
    return {
        "psnr_db": psnr_db(photo_bgr, rendered, compared) if pixels else float("nan"),
        "one_minus_ncc": local_one_minus_ncc(photo_bgr, rendered, compared) if pixels else 1.0,
        "pixels": pixels,
        "completeness": pixels / max(1, surface_pixels),
        "image_coverage": pixels / max(1, photo_bgr.shape[0] * photo_bgr.shape[1]),
    }


def self_check():
    """The metrics above against their definitions, computed the slow way on random images
    (no C++ needed; `--fresco-out` checks them against Fresco's own figures)."""
    rng = np.random.default_rng(1)
    h, w = 23, 31
    a = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
    b = np.clip(a.astype(int) + rng.integers(-40, 41, (h, w, 3)), 0, 255).astype(np.uint8)
    b[5:9, 3:8] = 77  # a flat patch: its boxes count as uncorrelated
    mask = np.zeros((h, w), np.uint8)
    mask[2:20, 4:29] = 255
    mask[10:12, 10:14] = 0
    m = mask != 0
    d = a[m].astype(float) - b[m].astype(float)
    want_psnr = 10 * math.log10(255.0 ** 2 / np.mean(d * d))
    ga, gb = (cv2.cvtColor(x, cv2.COLOR_BGR2GRAY).astype(float) for x in (a, b))
    reflect = lambda i, n: -i if i < 0 else (2 * (n - 1) - i if i >= n else i)  # REFLECT_101
    total, count = 0.0, 0
    for y in range(h):
        for x in range(w):
            box = [(reflect(y + dy, h), reflect(x + dx, w)) for dy in range(-4, 5)
                   for dx in range(-4, 5)]
            inside = all(0 > yy or yy >= h or 0 > xx or xx >= w or mask[yy, xx]
                         for yy in range(y - 4, y + 5) for xx in range(x - 4, x + 5))
            if not inside:
                continue
            pa = np.array([ga[p] for p in box])
            pb = np.array([gb[p] for p in box])
            cov = np.mean(pa * pb) - pa.mean() * pb.mean()
            total += 1 - cov / math.sqrt(max(pa.var() * pb.var(), 1e-6))
            count += 1
    want_ncc = total / count
    got_psnr, got_ncc = psnr_db(a, b, mask), local_one_minus_ncc(a, b, mask)
    ok = abs(got_psnr - want_psnr) < 1e-9 and abs(got_ncc - want_ncc) < 1e-9 and \
        math.isinf(psnr_db(a, a, mask)) and math.isnan(psnr_db(a, b, np.zeros_like(mask))) and \
        abs(local_one_minus_ncc(a, a, mask)) < 1e-9
    print(f"self-check: PSNR {got_psnr:.12f} vs {want_psnr:.12f}, local 1-NCC {got_ncc:.12f} vs "
          f"{want_ncc:.12f} ({count} boxes): {'ok' if ok else 'FAILED'}")
    return ok


def spread(values, higher_is_worse):
    """rephoto_report.cc's Spread: mean, median and worst of the finite values."""
    v = sorted(x for x in values if x is not None and math.isfinite(x))
    if not v:
        return {"mean": float("nan"), "median": float("nan"), "worst": float("nan")}
    return {"mean": sum(v) / len(v), "median": statistics.median(v),
            "worst": v[-1] if higher_is_worse else v[0]}


# ---------------------------------------------------------------------------------------------
# The project: camera, poses, frames (pipeline/core/project.h, capture.cc, colmap_text.cc).


class Camera:
    def __init__(self, width, height, fx, fy, cx, cy, source):
        self.width, self.height = int(width), int(height)
        self.fx, self.fy, self.cx, self.cy = float(fx), float(fy), float(cx), float(cy)
        self.source = source  # the file and model, for messages


def read_colmap_cameras(path):
    cameras = {}
    zero_distortion_models = {"SIMPLE_RADIAL": 3, "RADIAL": 3, "OPENCV": 4, "FULL_OPENCV": 4}
    for number, line in enumerate(open(path, encoding="utf-8"), 1):
        f = line.split()
        if not f or f[0].startswith("#"):
            continue
        cid, model, w, h, p = int(f[0]), f[1], int(f[2]), int(f[3]), [float(x) for x in f[4:]]
        where = f"{path}:{number}: camera {cid} ({model})"
        if model == "PINHOLE":
            fx, fy, cx, cy = p[:4]
        elif model == "SIMPLE_PINHOLE":
            fx, cx, cy = p[:3]
            fy = fx
        elif model in zero_distortion_models and not any(p[zero_distortion_models[model]:]):
            k = zero_distortion_models[model]
            fx, fy, cx, cy = (p[0], p[0], p[1], p[2]) if k == 3 else p[:4]
        else:
            raise Refused(f"{where}: lens distortion: Open3D's colour map takes pinhole cameras "
                          "only; undistort the frames and give a PINHOLE camera")
        cameras[cid] = Camera(w, h, fx, fy, cx - COLMAP_PIXEL_SHIFT, cy - COLMAP_PIXEL_SHIFT, where)
    if not cameras:
        raise Refused(f"{path}: holds no camera")
    return cameras


def read_mrcal_camera(path):
    text = "\n".join(line.split("#", 1)[0] for line in open(path, encoding="utf-8"))
    try:
        model = ast.literal_eval(text)
    except (ValueError, SyntaxError) as e:
        raise Refused(f"{path}: not an mrcal .cameramodel ({e})")
    lens = model.get("lensmodel", "")
    if lens != "LENSMODEL_PINHOLE":
        raise Refused(f"{path}: {lens}: Open3D's colour map takes pinhole cameras only; "
                      "undistort the frames and give a LENSMODEL_PINHOLE model")
    fx, fy, cx, cy = model["intrinsics"][:4]
    w, h = model["imagersize"]
    return {1: Camera(w, h, fx, fy, cx, cy, f"{path} ({lens})")}


def read_cameras(path):
    if os.path.isdir(path):
        path = os.path.join(path, "cameras.txt")
    if path.endswith(".cameramodel"):
        return read_mrcal_camera(path)
    return read_colmap_cameras(path)


def quaternion_matrix(w, x, y, z):
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def read_poses(path):
    """[(name, camera_id, R, t)] world to camera, and whether the file is a TUM trajectory."""
    if os.path.isdir(path):
        path = os.path.join(path, "images.txt")
    lines = open(path, encoding="utf-8").read().split("\n")
    data = [l for l in lines if l.strip() and not l.strip().startswith("#")]
    tum = False
    if data:
        f = data[0].split()
        if len(f) == 8:
            try:
                [float(x) for x in f]
                tum = True
            except ValueError:
                tum = os.path.basename(path) != "images.txt" and _is_float(f[0])
    poses = []
    if tum:  # timestamp tx ty tz qx qy qz qw, camera to world; matched to frames in order
        for l in data:
            _, tx, ty, tz, qx, qy, qz, qw = (float(x) for x in l.split())
            r_wc = quaternion_matrix(qw, qx, qy, qz)
            r = r_wc.T
            poses.append((None, None, r, -r @ np.array([tx, ty, tz])))
        return poses, True
    i = 0
    while i < len(lines):  # COLMAP: a pose line, then its points line (possibly empty)
        line = lines[i]
        i += 1
        if not line.strip() or line.strip().startswith("#"):
            continue
        f = line.split()
        qw, qx, qy, qz, tx, ty, tz = (float(x) for x in f[1:8])
        name = line.split(None, 9)[9].strip()
        poses.append((name, int(f[8]), quaternion_matrix(qw, qx, qy, qz), np.array([tx, ty, tz])))
        i += 1  # the 2D points
    return poses, False


def _is_float(s):
    try:
        float(s)
        return True
    except ValueError:
        return False


def stem(name):
    base = os.path.basename(name)
    return base[:base.rfind(".")] if "." in base[1:] else base


def resolve(project_dir, path):
    return path if os.path.isabs(path) else os.path.normpath(os.path.join(project_dir, path))


class Posed:
    def __init__(self, counter, frame_name, pose_name, camera_id, camera, r, t, path):
        self.counter, self.frame_name, self.pose_name = counter, frame_name, pose_name
        self.camera_id, self.camera, self.r, self.t, self.path = camera_id, camera, r, t, path
        self.name = pose_name or frame_name  # as rephoto.json names it


def load_project(path):
    project_dir = os.path.dirname(os.path.abspath(path))
    try:
        doc = json.load(open(path, encoding="utf-8"))
    except (OSError, ValueError) as e:
        raise Refused(f"{path}: cannot read the project ({e})")
    if doc.get("fresco") != 1 or "streams" in doc:
        raise Refused(f"{path}: one video stream (a version-1 project) is scored here")
    for key in ("scene", "camera", "video", "poses"):
        if key not in doc:
            raise Refused(f"{path}: {key}: missing")
    for key in ("scene", "camera", "video", "poses"):
        if not os.path.exists(resolve(project_dir, doc[key])):
            raise Refused(f"{path}: {key}: '{doc[key]}' does not exist "
                          f"({resolve(project_dir, doc[key])})")
    video = resolve(project_dir, doc["video"])
    if not os.path.isdir(video):
        raise Refused(f"{path}: video: '{doc['video']}': a folder of images is scored here "
                      "(not a video file or a live source)")
    scene = resolve(project_dir, doc["scene"])
    if os.path.splitext(scene)[1].lower() not in (".ply", ".obj"):
        raise Refused(f"{path}: scene: PLY or OBJ scored here (Open3D's glTF reader is not "
                      "trusted to apply node transforms as Fresco does)")
    cameras = read_cameras(resolve(project_dir, doc["camera"]))
    poses, is_tum = read_poses(resolve(project_dir, doc["poses"]))
    max_frames = int(doc.get("pipeline", {}).get("max_frames", 0))
    # The video folder as FolderSource lists it: image files, no hidden ones, sorted by name.
    names = sorted(n for n in os.listdir(video)
                   if not n.startswith(".") and os.path.splitext(n)[1].lower() in IMAGE_EXTENSIONS
                   and os.path.isfile(os.path.join(video, n)))
    if max_frames > 0:
        names = names[:max_frames]
    # Capture::PoseForFrame: TUM by index; COLMAP by exact name, then by a pose's file name,
    # then by a stem only one pose has.
    by_name, by_stem = {}, {}
    if not is_tum:
        for i, (name, _, _, _) in enumerate(poses):
            by_name[name] = i
            by_stem[stem(name)] = -1 if stem(name) in by_stem else i
        folder = set(names)
        for i, (name, _, _, _) in enumerate(poses):
            if os.path.basename(name) in folder:
                by_name.setdefault(os.path.basename(name), i)
    posed = []
    for counter, frame in enumerate(names):
        if is_tum:
            index = counter if counter < len(poses) else None
        else:
            index = by_name.get(frame)
            if index is None and by_stem.get(stem(frame), -1) >= 0:
                index = by_stem[stem(frame)]
        if index is None:
            continue
        pose_name, camera_id, r, t = poses[index]
        camera = cameras.get(camera_id) if camera_id is not None else None
        if camera is None and len(cameras) == 1:  # Capture::CameraFor
            camera_id, camera = next(iter(cameras.items()))
        if camera is None:
            raise Refused(f"{path}: poses: image '{pose_name}': camera {camera_id} not found")
        posed.append(Posed(counter, frame, pose_name, camera_id, camera, r, t,
                           os.path.join(video, frame)))
    return {"path": path, "dir": project_dir, "doc": doc, "scene": scene, "video": video,
            "camera_path": resolve(project_dir, doc["camera"]), "frames_read": len(names),
            "posed": posed, "is_tum": is_tum}


# ---------------------------------------------------------------------------------------------
# Geometry: which triangle each pixel sees, and where on it (pixel centres, no culling, near
# plane 1 mm: Fresco's RenderOptions()).


def camera_vertices(vertices, frame):
    return vertices @ frame.r.T + frame.t


def surface_at_ids(v_cam, triangles, tri_id, cam):
    """Exact ray/triangle hit for each pixel's triangle: camera z, barycentrics (b1, b2)."""
    ys, xs = np.nonzero(tri_id >= 0)
    tri = triangles[tri_id[ys, xs]]
    d = np.stack([(xs - cam.cx) / cam.fx, (ys - cam.cy) / cam.fy, np.ones(len(xs))], axis=1)
    a, b, c = v_cam[tri[:, 0]], v_cam[tri[:, 1]], v_cam[tri[:, 2]]
    e1, e2 = b - a, c - a
    p = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, p)
    det = np.where(det == 0, 1e-300, det)
    s = -a
    b1 = np.einsum("ij,ij->i", s, p) / det
    q = np.cross(s, e1)
    b2 = np.einsum("ij,ij->i", d, q) / det
    z = np.einsum("ij,ij->i", e2, q) / det
    return ys, xs, z, b1, b2


def rasterize_ids(v_cam, triangles, cam, near=1e-3, budget=4_000_000):
    """A z-buffer in numpy: the nearest triangle at each pixel centre (-1 where none)."""
    h, w = cam.height, cam.width
    z = v_cam[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        u = cam.fx * v_cam[:, 0] / z + cam.cx
        v = cam.fy * v_cam[:, 1] / z + cam.cy
    tz = z[triangles]
    in_front = (tz > near).all(axis=1)
    crossing = int(((tz > near).any(axis=1) & ~in_front).sum())
    tu, tv = u[triangles], v[triangles]
    with np.errstate(invalid="ignore"):
        x0 = np.clip(np.ceil(tu.min(1)), 0, w).astype(np.int64)
        x1 = np.clip(np.floor(tu.max(1)), -1, w - 1).astype(np.int64)
        y0 = np.clip(np.ceil(tv.min(1)), 0, h).astype(np.int64)
        y1 = np.clip(np.floor(tv.max(1)), -1, h - 1).astype(np.int64)
    live = in_front & (x1 >= x0) & (y1 >= y0)
    size = np.where(live, np.maximum(x1 - x0 + 1, y1 - y0 + 1), 0)
    best_z = np.full(h * w, np.inf)
    best_id = np.full(h * w, -1, np.int64)
    s = 1
    while True:
        sel = np.nonzero(live & (size <= s) & (size > s // 2))[0]
        if len(sel):
            dy, dx = np.divmod(np.arange(s * s), s)
            chunk = max(1, budget // (s * s))
            for at in range(0, len(sel), chunk):
                k = sel[at:at + chunk]
                px = x0[k, None] + dx[None, :]
                py = y0[k, None] + dy[None, :]
                ok = (px <= x1[k, None]) & (py <= y1[k, None])
                u0, u1, u2 = (tu[k, i, None] for i in range(3))
                v0, v1, v2 = (tv[k, i, None] for i in range(3))
                area = (u1 - u0) * (v2 - v0) - (u2 - u0) * (v1 - v0)
                area = np.where(area == 0, np.nan, area)
                l0 = ((u1 - px) * (v2 - py) - (u2 - px) * (v1 - py)) / area
                l1 = ((u2 - px) * (v0 - py) - (u0 - px) * (v2 - py)) / area
                l2 = 1.0 - l0 - l1
                with np.errstate(invalid="ignore"):
                    ok &= (l0 >= 0) & (l1 >= 0) & (l2 >= 0)
                zz = 1.0 / (l0 / tz[k, 0, None] + l1 / tz[k, 1, None] + l2 / tz[k, 2, None])
                pix = (py * w + px)[ok]
                zz = zz[ok]
                ids = np.broadcast_to(k[:, None], ok.shape)[ok]
                order = np.lexsort((zz, pix))
                pix, zz, ids = pix[order], zz[order], ids[order]
                first = np.ones(len(pix), bool)
                first[1:] = pix[1:] != pix[:-1]
                pix, zz, ids = pix[first], zz[first], ids[first]
                nearer = zz < best_z[pix]
                best_z[pix[nearer]] = zz[nearer]
                best_id[pix[nearer]] = ids[nearer]
        if s >= max(h, w) * 2 or not (live & (size > s)).any():
            break
        s *= 2
    return best_id.reshape(h, w), crossing


class FrescoIds:
    """Triangle ids from `fresco render --ids` (Fresco's rasterizer) for every posed frame,
    mapped from Fresco's triangle list (degenerate triangles dropped) to the file's."""

    def __init__(self, binary, project, frames, vertices, triangles, workdir):
        e1 = vertices[triangles[:, 1]] - vertices[triangles[:, 0]]
        e2 = vertices[triangles[:, 2]] - vertices[triangles[:, 0]]
        area = 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1)
        self.kept = np.nonzero(area >= MIN_TRIANGLE_AREA)[0]
        self.dir = os.path.join(workdir, "ids")
        poses = os.path.join(workdir, "images.txt")
        with open(poses, "w", encoding="utf-8") as f:
            for i in frames:
                p = project["posed"][i]
                q = rotation_quaternion(p.r)
                f.write(f"{i + 1} {q[0]!r} {q[1]!r} {q[2]!r} {q[3]!r} {p.t[0]!r} {p.t[1]!r} "
                        f"{p.t[2]!r} {p.camera_id} f{i:06d}.png\n\n")
        command = [binary, "render", project["scene"], "--camera", project["camera_path"],
                   "--poses", poses, "--out", self.dir, "--ids", "--depth", "--quiet"]
        done = subprocess.run(command, capture_output=True, text=True)
        if done.returncode != 0:
            raise Refused("fresco render failed (" + " ".join(command) + "): " +
                          (done.stderr.strip() or done.stdout.strip()))

    def ids(self, index):
        bgra = cv2.imread(os.path.join(self.dir, f"f{index:06d}.ids.png"), cv2.IMREAD_UNCHANGED)
        raw = (bgra[:, :, 2].astype(np.int64) + 256 * bgra[:, :, 1].astype(np.int64) +
               65536 * bgra[:, :, 0].astype(np.int64)) - 1
        out = np.full(raw.shape, -1, np.int64)
        ok = raw >= 0
        out[ok] = self.kept[raw[ok]]
        return out

    def depth_mm(self, index):
        return cv2.imread(os.path.join(self.dir, f"f{index:06d}.depth.png"), cv2.IMREAD_UNCHANGED)


def rotation_quaternion(r):
    """(w, x, y, z) of a rotation matrix."""
    tr = np.trace(r)
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        return (0.25 * s, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s,
                (r[1, 0] - r[0, 1]) / s)
    i = int(np.argmax(np.diag(r)))
    j, k = (i + 1) % 3, (i + 2) % 3
    s = math.sqrt(1.0 + r[i, i] - r[j, j] - r[k, k]) * 2
    q = [0.0, 0.0, 0.0, 0.0]
    q[0] = (r[k, j] - r[j, k]) / s
    q[1 + i] = 0.25 * s
    q[1 + j] = (r[j, i] + r[i, j]) / s
    q[1 + k] = (r[k, i] + r[i, k]) / s
    return tuple(q)


# ---------------------------------------------------------------------------------------------
# Depth for Open3D's visibility test.


def tum_capture_depth(project, scale):
    """{frame path: depth path} for a TUM RGB-D capture (video folder .../rgb, .../depth)."""
    video = project["video"].rstrip("/")
    root, depth_dir = os.path.dirname(video), os.path.join(os.path.dirname(video), "depth")
    if os.path.basename(video) != "rgb" or not os.path.isdir(depth_dir):
        return None
    pairs = {}
    listing = os.path.join(root, "frames.txt")
    if os.path.isfile(listing):  # index t_rgb rgb_file t_depth depth_file ...
        for line in open(listing, encoding="utf-8"):
            f = line.split()
            if len(f) >= 5 and not f[0].startswith("#"):
                pairs[os.path.basename(f[2])] = os.path.join(root, f[4])
    else:  # nearest depth time, within 20 ms (TUM's associate.py)
        stamps = sorted((float(stem(n)), n) for n in os.listdir(depth_dir) if _is_float(stem(n)))
        times = np.array([s for s, _ in stamps])
        for p in project["posed"]:
            if _is_float(stem(p.frame_name)) and len(times):
                j = int(np.argmin(np.abs(times - float(stem(p.frame_name)))))
                if abs(times[j] - float(stem(p.frame_name))) < 0.02:
                    pairs[p.frame_name] = os.path.join(depth_dir, stamps[j][1])
    out = {}
    for p in project["posed"]:
        if p.frame_name not in pairs:
            raise Refused(f"{depth_dir}: no depth for frame {p.frame_name}")
        out[p.path] = pairs[p.frame_name]
    return out


# ---------------------------------------------------------------------------------------------
# Fresco's rephoto output (app/rephoto_command.cc): rephoto.json and views/NAME.png.


def file_stem(name):
    s = name[:name.rfind(".")] if "." in name else name
    s = "".join(c if (c.isascii() and c.isalnum()) or c in "-_" else "_" for c in s)
    return s or "frame"


def read_fresco_view(folder, name, height, width):
    """Fresco's render (black where not compared) and photo from views/NAME.png."""
    image = cv2.imread(os.path.join(folder, "views", file_stem(name) + ".png"), cv2.IMREAD_COLOR)
    if image is None:
        return None, None
    caption = max(24, height // 30)  # SideBySide's caption strip
    body = image[caption:caption + height]
    return body[:, :width].copy(), body[:, width:2 * width].copy()


# ---------------------------------------------------------------------------------------------


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    if "--self-check" in sys.argv[1:]:
        sys.exit(0 if self_check() else 1)
    ap.add_argument("project")
    ap.add_argument("--out", required=True)
    ap.add_argument("--every", type=int, default=1)
    ap.add_argument("--fresco-out", action="append", default=[],
                    help="a `fresco rephoto --out` folder (repeatable)")
    ap.add_argument("--renderer", choices=["auto", "fresco", "numpy"], default="auto")
    ap.add_argument("--fresco", default=os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                     "..", "..", "build", "app", "fresco"))
    ap.add_argument("--depth", choices=["auto", "render", "capture"], default="auto")
    ap.add_argument("--depth-scale", type=float, default=5000.0, help="capture depth units/m")
    ap.add_argument("--views", action="store_true")
    ap.add_argument("--frames", type=int, default=0, help="score only the first K cases (debug)")
    # Open3D's RigidOptimizerOption; its defaults except maximum_allowable_depth (2.5 m would
    # drop whole scenes farther than that; the depth comes from the mesh or the capture)
    # and invisible_vertex_color_knn (0: unseen vertices stay unpainted, as Fresco's texels).
    ap.add_argument("--maximum-allowable-depth", type=float, default=1e30)
    ap.add_argument("--depth-threshold-for-visibility-check", type=float, default=0.03)
    ap.add_argument("--depth-threshold-for-discontinuity-check", type=float, default=0.1)
    ap.add_argument("--half-dilation-kernel-size-for-discontinuity-map", type=int, default=3)
    ap.add_argument("--image-boundary-margin", type=int, default=10)
    ap.add_argument("--invisible-vertex-color-knn", type=int, default=0,
                    help="> 0: Open3D fills unseen vertices from k neighbours; every surface "
                         "pixel is then compared")
    ap.add_argument("--o3d-scale", type=float, default=1.0,
                    help="multiply Open3D's distance thresholds (visibility, discontinuity, "
                         "maximum depth) by this: its defaults are metres for a Kinect at ~1 m; "
                         "a scene in other units or seen from afar needs them scaled")
    ap.add_argument("--sample-shift", type=float, default=0.0,
                    help="add this to the cx, cy Open3D gets (0.5 turns its truncating colour "
                         "lookup into nearest-pixel; 0 = as a user would call it)")
    args = ap.parse_args()
    if args.every < 1:
        ap.error("--every: must be >= 1")

    rusage0 = resource.getrusage(resource.RUSAGE_SELF)
    wall0 = time.time()
    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    try:
        project = load_project(args.project)
    except Refused as e:
        sys.exit(f"open3d_colormap: {e}")
    posed = project["posed"]
    if len(posed) < 2:
        sys.exit(f"open3d_colormap: {args.project}: rephotography needs at least 2 frames "
                 f"with poses (found {len(posed)})")
    cases = list(range(0, len(posed), args.every))
    if args.frames > 0:
        cases = cases[:args.frames]
    os.makedirs(args.out, exist_ok=True)

    mesh = o3d.io.read_triangle_mesh(project["scene"])
    vertices = np.asarray(mesh.vertices).astype(np.float32).astype(np.float64)  # as Assimp
    triangles = np.asarray(mesh.triangles).astype(np.int64)
    if len(triangles) == 0:
        sys.exit(f"open3d_colormap: {project['scene']}: no triangles")
    mesh.vertex_colors = o3d.utility.Vector3dVector()  # whatever colours it had play no part
    print(f"{args.project}: {len(posed)} posed frames of {project['frames_read']}, "
          f"{len(cases)} left out in turn (--every {args.every}); mesh {len(vertices)} vertices, "
          f"{len(triangles)} triangles", file=sys.stderr)

    # The depth Open3D's visibility test reads.
    depth_mode = args.depth
    try:
        capture_depth = (tum_capture_depth(project, args.depth_scale)
                         if depth_mode != "render" else None)
    except Refused as e:
        sys.exit(f"open3d_colormap: {e}")
    if depth_mode == "capture" and capture_depth is None:
        sys.exit(f"open3d_colormap: --depth capture: {project['video']} is not a TUM RGB-D "
                 "capture's rgb folder with depth/ beside it")
    depth_mode = "capture" if capture_depth else "render"

    # Which triangle each pixel sees: at every posed frame when the depth is rendered, else
    # at the left-out ones.
    renderer = args.renderer
    if renderer == "auto":
        renderer = "fresco" if os.access(args.fresco, os.X_OK) else "numpy"
    case_set = set(cases)
    needed = list(range(len(posed))) if depth_mode == "render" else cases
    workdir = tempfile.mkdtemp(prefix="open3d_colormap.")
    prep_cpu0 = time.process_time()
    t0 = time.time()
    surfaces = {}  # left-out frame: (ys, xs, b1, b2, tri) of its surface pixels
    depths = {}    # frame: camera z where the mesh is seen, 0 elsewhere (float32)
    checks = {"renderer": renderer}
    try:
        fresco_ids = (FrescoIds(args.fresco, project, needed, vertices, triangles, workdir)
                      if renderer == "fresco" else None)
        child = resource.getrusage(resource.RUSAGE_CHILDREN)
        checks["fresco_render_cpu_s"] = child.ru_utime + child.ru_stime
        for i in needed:
            p = posed[i]
            v_cam = camera_vertices(vertices, p)
            if fresco_ids is not None:
                tri_id = fresco_ids.ids(i)
                if tri_id.shape != (p.camera.height, p.camera.width):
                    raise Refused(f"fresco render: ids of {p.name} are {tri_id.shape[::-1]}, "
                                  f"not the camera's {p.camera.width}x{p.camera.height}")
            else:
                tri_id, crossing = rasterize_ids(v_cam, triangles, p.camera)
                if crossing:
                    skipped = checks.setdefault("near_plane_crossing_triangles_skipped", {})
                    skipped[p.name] = crossing
            ys, xs, z, b1, b2 = surface_at_ids(v_cam, triangles, tri_id, p.camera)
            if depth_mode == "render":
                depth = np.zeros((p.camera.height, p.camera.width), np.float32)
                depth[ys, xs] = z
                depths[i] = depth
            if i in case_set:
                surfaces[i] = (ys, xs, b1, b2, tri_id[ys, xs])
            if fresco_ids is not None and i == cases[0]:
                # The id mapping is right when the depth from it is Fresco's own depth.
                mm = fresco_ids.depth_mm(i)[ys, xs].astype(np.float64)
                ok = (mm > 0) & (mm < 65535)
                err = np.abs(mm[ok] - z[ok] * 1000.0)
                checks["fresco_depth_vs_ids_mm"] = {
                    "frame": p.name, "median": float(np.median(err)),
                    "p99": float(np.percentile(err, 99)), "max": float(err.max())}
                if np.percentile(err, 99) > 1.0:
                    raise Refused("fresco render's triangle ids do not match the mesh read here "
                                  f"(depth off by {np.percentile(err, 99):.1f} mm at the 99th "
                                  "percentile); use --renderer numpy")
                # And the numpy z-buffer agrees with Fresco's rasterizer.
                own, _ = rasterize_ids(v_cam, triangles, p.camera)
                surf_f, surf_n = tri_id >= 0, own >= 0
                checks["numpy_vs_fresco_ids"] = {
                    "frame": p.name,
                    "surface_pixels_fresco": int(surf_f.sum()),
                    "surface_pixels_numpy": int(surf_n.sum()),
                    "same_triangle_fraction": float((own[surf_f] == tri_id[surf_f]).mean()),
                    "surface_disagreeing_pixels": int((surf_f != surf_n).sum())}
    except Refused as e:
        shutil.rmtree(workdir, ignore_errors=True)
        sys.exit(f"open3d_colormap: {e}")
    shutil.rmtree(workdir, ignore_errors=True)

    # Photos and Open3D's inputs.
    photos, rgbd, params = [], [], []
    for i, p in enumerate(posed):
        photo = cv2.imread(p.path, cv2.IMREAD_COLOR)
        if photo is None:
            sys.exit(f"open3d_colormap: {p.path}: cannot decode the image")
        if photo.shape[:2] != (p.camera.height, p.camera.width):
            sys.exit(f"open3d_colormap: {p.path}: frame is {photo.shape[1]}x{photo.shape[0]} but "
                     f"the camera is {p.camera.width}x{p.camera.height}")
        photos.append(photo)
        if capture_depth:
            raw = cv2.imread(capture_depth[p.path], cv2.IMREAD_UNCHANGED)
            depth = raw.astype(np.float32) / np.float32(args.depth_scale)
        else:
            depth = depths.pop(i)
        color = o3d.geometry.Image(np.ascontiguousarray(photo[:, :, ::-1]))
        rgbd.append(o3d.geometry.RGBDImage.create_from_color_and_depth(
            color, o3d.geometry.Image(depth), depth_scale=1.0, depth_trunc=1e30,
            convert_rgb_to_intensity=False))
        cam = o3d.camera.PinholeCameraParameters()
        cam.intrinsic = o3d.camera.PinholeCameraIntrinsic(
            p.camera.width, p.camera.height, p.camera.fx, p.camera.fy,
            p.camera.cx + args.sample_shift, p.camera.cy + args.sample_shift)
        extrinsic = np.eye(4)
        extrinsic[:3, :3], extrinsic[:3, 3] = p.r, p.t
        cam.extrinsic = extrinsic
        params.append(cam)
    prep = {"cpu_s": time.process_time() - prep_cpu0, "wall_s": time.time() - t0}

    option = o3d.pipelines.color_map.RigidOptimizerOption(
        maximum_iteration=0,
        maximum_allowable_depth=args.maximum_allowable_depth * args.o3d_scale,
        depth_threshold_for_visibility_check=(
            args.depth_threshold_for_visibility_check * args.o3d_scale),
        depth_threshold_for_discontinuity_check=(
            args.depth_threshold_for_discontinuity_check * args.o3d_scale),
        half_dilation_kernel_size_for_discontinuity_map=(
            args.half_dilation_kernel_size_for_discontinuity_map),
        image_boundary_margin=args.image_boundary_margin,
        invisible_vertex_color_knn=args.invisible_vertex_color_knn)

    fresco_runs = []
    for folder in args.fresco_out:
        doc = json.load(open(os.path.join(folder, "rephoto.json"), encoding="utf-8"))
        if doc.get("every") != args.every:
            print(f"warning: {folder}: rephoto ran with --every {doc.get('every')}, "
                  f"not {args.every}", file=sys.stderr)
        fresco_runs.append((folder, doc, {f["name"]: f for f in doc["frames"]}))

    rows = []
    if args.views:
        os.makedirs(os.path.join(args.out, "views"), exist_ok=True)
    for n, k in enumerate(cases):
        p = posed[k]
        others = [j for j in range(len(posed)) if j != k]
        trajectory = o3d.camera.PinholeCameraTrajectory()
        trajectory.parameters = [params[j] for j in others]
        cpu0, w0 = time.process_time(), time.time()
        painted, _ = o3d.pipelines.color_map.run_rigid_optimizer(
            mesh, [rgbd[j] for j in others], trajectory, option)
        cpu, wall = time.process_time() - cpu0, time.time() - w0
        colors = np.asarray(painted.vertex_colors)
        seen = np.any(colors > 0, axis=1) if args.invisible_vertex_color_knn <= 0 else \
            np.ones(len(colors), bool)

        ys, xs, b1, b2, tri = surfaces[k]
        corners = triangles[tri]
        covered = seen[corners].all(axis=1)
        rgb = ((1.0 - b1 - b2)[:, None] * colors[corners[:, 0]] + b1[:, None] *
               colors[corners[:, 1]] + b2[:, None] * colors[corners[:, 2]])
        bgr8 = np.clip(np.rint(rgb[:, ::-1] * 255.0), 0, 255).astype(np.uint8)
        h, w = p.camera.height, p.camera.width
        rendered = np.zeros((h, w, 3), np.uint8)
        compared = np.zeros((h, w), np.uint8)
        rendered[ys[covered], xs[covered]] = bgr8[covered]
        compared[ys[covered], xs[covered]] = 255
        photo = photos[k]
        row = {"name": p.name, "counter": p.counter, "frames_painted": len(others),
               "open3d_cpu_s": cpu, "open3d_wall_s": wall,
               "vertices_seen": float(seen.mean())}
        row.update(score(photo, rendered, compared, len(ys)))
        if args.views:
            side = np.zeros((h + max(24, h // 30), 2 * w, 3), np.uint8)
            side[-h:, :w], side[-h:, w:] = rendered, photo
            cv2.putText(side, f"{p.name}  Open3D average of the others: {row['psnr_db']:.2f} dB, "
                        f"1-NCC {row['one_minus_ncc']:.3f} | photo",
                        (8, max(24, h // 30) * 3 // 4), cv2.FONT_HERSHEY_SIMPLEX,
                        max(24, h // 30) / 40.0, (255, 255, 255), 1, cv2.LINE_AA)
            cv2.imwrite(os.path.join(args.out, "views", file_stem(p.name) + ".png"), side)
        # Against Fresco's runs: its render and photo re-scored here, and both on the pixels
        # both painted.
        row["fresco"] = []
        for folder, doc, by_name in fresco_runs:
            f = by_name.get(p.name)
            entry = {"run": folder, "settings": doc.get("settings", [])}
            fr, fphoto = read_fresco_view(folder, p.name, h, w)
            if f is None or fr is None:
                entry["missing"] = True
                row["fresco"].append(entry)
                continue
            fmask = np.any(fr != 0, axis=2).astype(np.uint8) * 255
            entry.update({
                "psnr_db": f["psnr_db"], "one_minus_ncc": f["one_minus_ncc"],
                "completeness": f["completeness"], "pixels": f["pixels"],
                "paint_seconds": f["paint_seconds"],
                "photo_same_as_read_here": bool(np.array_equal(fphoto, photo)),
                "mask_pixels_from_view": int(np.count_nonzero(fmask)),
                "psnr_db_recomputed": psnr_db(fphoto, fr, fmask),
                "one_minus_ncc_recomputed": local_one_minus_ncc(fphoto, fr, fmask)})
            both = ((compared != 0) & (fmask != 0)).astype(np.uint8) * 255
            entry["common_pixels"] = int(np.count_nonzero(both))
            entry["common_open3d"] = {"psnr_db": psnr_db(photo, rendered, both),
                                      "one_minus_ncc": local_one_minus_ncc(photo, rendered, both)}
            fr_both = fr.copy()
            fr_both[both == 0] = 0
            entry["common_fresco"] = {"psnr_db": psnr_db(photo, fr_both, both),
                                      "one_minus_ncc": local_one_minus_ncc(photo, fr_both, both)}
            row["fresco"].append(entry)
        rows.append(row)
        print(f"[{n + 1}/{len(cases)}] {p.name}: {row['psnr_db']:.2f} dB, 1-NCC "
              f"{row['one_minus_ncc']:.3f}, completeness {row['completeness']:.3f} "
              f"(Open3D {cpu:.1f} CPU s, {wall:.1f} s)", file=sys.stderr)

    rusage1 = resource.getrusage(resource.RUSAGE_SELF)
    child = resource.getrusage(resource.RUSAGE_CHILDREN)
    summary = {
        "frames": len(rows),
        "psnr_db": spread([r["psnr_db"] for r in rows], False),
        "one_minus_ncc": spread([r["one_minus_ncc"] for r in rows], True),
        "completeness": spread([r["completeness"] for r in rows], False),
        "open3d_cpu_s": spread([r["open3d_cpu_s"] for r in rows], True),
        "open3d_cpu_s_total": sum(r["open3d_cpu_s"] for r in rows),
        "open3d_wall_s_total": sum(r["open3d_wall_s"] for r in rows),
        "preparation": prep,
        "script_cpu_s": (rusage1.ru_utime + rusage1.ru_stime) -
                        (rusage0.ru_utime + rusage0.ru_stime),
        "children_cpu_s": child.ru_utime + child.ru_stime,
        "wall_s": time.time() - wall0,
    }
    fresco_summary = []
    for r_index, (folder, doc, _) in enumerate(fresco_runs):
        got = [r["fresco"][r_index] for r in rows if not r["fresco"][r_index].get("missing")]
        fs = {"run": folder, "settings": doc.get("settings", []), "frames": len(got)}
        if got:
            fs["psnr_db"] = spread([g["psnr_db"] for g in got], False)
            fs["one_minus_ncc"] = spread([g["one_minus_ncc"] for g in got], True)
            fs["completeness"] = spread([g["completeness"] for g in got], False)
            fs["paint_seconds"] = spread([g["paint_seconds"] for g in got], True)
            fs["common_open3d"] = {
                "psnr_db": spread([g["common_open3d"]["psnr_db"] for g in got], False),
                "one_minus_ncc": spread([g["common_open3d"]["one_minus_ncc"] for g in got], True)}
            fs["common_fresco"] = {
                "psnr_db": spread([g["common_fresco"]["psnr_db"] for g in got], False),
                "one_minus_ncc": spread([g["common_fresco"]["one_minus_ncc"] for g in got], True)}
            fs["metric_check"] = {
                "max_abs_psnr_db_difference": max(abs(g["psnr_db"] - g["psnr_db_recomputed"])
                                                  for g in got),
                "max_abs_one_minus_ncc_difference": max(
                    abs(g["one_minus_ncc"] - g["one_minus_ncc_recomputed"]) for g in got),
                "photos_identical": all(g["photo_same_as_read_here"] for g in got),
                "mask_pixel_difference_max": max(abs(g["pixels"] - g["mask_pixels_from_view"])
                                                 for g in got)}
        fresco_summary.append(fs)

    option_doc = {"maximum_iteration": 0,
                  "maximum_allowable_depth": args.maximum_allowable_depth * args.o3d_scale,
                  "depth_threshold_for_visibility_check":
                      args.depth_threshold_for_visibility_check * args.o3d_scale,
                  "depth_threshold_for_discontinuity_check":
                      args.depth_threshold_for_discontinuity_check * args.o3d_scale,
                  "half_dilation_kernel_size_for_discontinuity_map":
                      args.half_dilation_kernel_size_for_discontinuity_map,
                  "image_boundary_margin": args.image_boundary_margin,
                  "invisible_vertex_color_knn": args.invisible_vertex_color_knn,
                  "sample_shift_px": args.sample_shift}
    doc = {"project": args.project, "every": args.every, "frames_read": project["frames_read"],
           "frames_posed": len(posed), "open3d_version": o3d.__version__,
           "open3d_option": option_doc, "depth": depth_mode, "checks": checks,
           "frames": rows, "summary": summary, "fresco": fresco_summary}
    with open(os.path.join(args.out, "open3d_colormap.json"), "w", encoding="utf-8") as f:
        json.dump(doc, f, indent=2, default=lambda x: None, allow_nan=True)
        f.write("\n")
    text = markdown(doc)
    with open(os.path.join(args.out, "open3d_colormap.md"), "w", encoding="utf-8") as f:
        f.write(text)
    print(text)


def fmt(x, digits):
    return "nan" if x is None or not math.isfinite(x) else f"{x:.{digits}f}"


def markdown(doc):
    s = doc["summary"]
    runs = doc["fresco"]
    out = [f"Open3D {doc['open3d_version']} colour map, plain average (maximum_iteration=0), "
           f"scored as `fresco rephoto --every {doc['every']}` on {doc['project']}: "
           f"{s['frames']} frames left out in turn (of {doc['frames_posed']} with poses); "
           f"visibility depth: {doc['depth']}; renderer: {doc['checks']['renderer']}", ""]
    head = ("| frame | PSNR dB | 1 - NCC | completeness | image covered | painted from | "
            "Open3D CPU s |")
    sep = "|---|---|---|---|---|---|---|"
    for i, _ in enumerate(runs):
        head += f" F{i} PSNR | F{i} 1-NCC |"
        sep += "---|---|"
    out += [head, sep]
    for r in doc["frames"]:
        line = (f"| {r['name']} | {fmt(r['psnr_db'], 2)} | {fmt(r['one_minus_ncc'], 3)} | "
                f"{fmt(r['completeness'], 3)} | {fmt(r['image_coverage'], 3)} | "
                f"{r['frames_painted']} | {fmt(r['open3d_cpu_s'], 1)} |")
        for e in r["fresco"]:
            line += (" - | - |" if e.get("missing") else
                     f" {fmt(e['psnr_db'], 2)} | {fmt(e['one_minus_ncc'], 3)} |")
        out.append(line)
    for label in ("mean", "median", "worst"):
        line = (f"| **{label}** | {fmt(s['psnr_db'][label], 2)} | "
                f"{fmt(s['one_minus_ncc'][label], 3)} | {fmt(s['completeness'][label], 3)} | | | "
                f"{fmt(s['open3d_cpu_s'][label], 1)} |")
        for fs in runs:
            line += (f" {fmt(fs['psnr_db'][label], 2)} | {fmt(fs['one_minus_ncc'][label], 3)} |"
                     if fs["frames"] else " - | - |")
        out.append(line)
    if runs:
        out.append("")
    for i, fs in enumerate(runs):
        out.append(f"F{i} = `fresco rephoto` in {fs['run']}, settings "
                   f"{' '.join(fs['settings']) or 'defaults'}  ")

    def spread_cells(psnr, ncc):
        return (f"{fmt(psnr['mean'], 2)} / {fmt(psnr['median'], 2)} / {fmt(psnr['worst'], 2)} | "
                f"{fmt(ncc['mean'], 3)} / {fmt(ncc['median'], 3)} / {fmt(ncc['worst'], 3)}")

    out += ["", "| painting | pixels | PSNR dB mean / median / worst | "
            "1 - NCC mean / median / worst | completeness |", "|---|---|---|---|---|",
            f"| Open3D average | its own | {spread_cells(s['psnr_db'], s['one_minus_ncc'])} | "
            f"{fmt(s['completeness']['mean'], 3)} |"]
    for i, fs in enumerate(runs):
        if not fs["frames"]:
            continue
        out.append(f"| F{i} | its own | {spread_cells(fs['psnr_db'], fs['one_minus_ncc'])} | "
                   f"{fmt(fs['completeness']['mean'], 3)} |")
        for who, key in (("Open3D average", "common_open3d"), (f"F{i}", "common_fresco")):
            out.append(f"| {who} | painted by both (Open3D and F{i}) | "
                       f"{spread_cells(fs[key]['psnr_db'], fs[key]['one_minus_ncc'])} | |")
    out.append("")
    out.append(f"Open3D: {fmt(s['open3d_cpu_s_total'], 1)} CPU s in all "
               f"({fmt(s['open3d_wall_s_total'], 1)} s wall); preparation (geometry, depths, "
               f"images) {fmt(s['preparation']['cpu_s'], 1)} CPU s; the whole script "
               f"{fmt(s['script_cpu_s'], 1)} CPU s, child processes (fresco render) "
               f"{fmt(s['children_cpu_s'], 1)} CPU s, {fmt(s['wall_s'], 1)} s wall.")
    for i, fs in enumerate(runs):
        if not fs["frames"]:
            continue
        c = fs["metric_check"]
        out.append(f"Metric check, F{i}: its views re-scored here differ from its rephoto.json by "
                   f"at most {c['max_abs_psnr_db_difference']:.2g} dB and "
                   f"{c['max_abs_one_minus_ncc_difference']:.2g} in 1 - NCC (compared pixels "
                   f"taken from the views: off by at most {c['mask_pixel_difference_max']}; "
                   f"its photos identical to those read here: {c['photos_identical']}).")
    ch = doc["checks"]
    if "fresco_depth_vs_ids_mm" in ch:
        d, a = ch["fresco_depth_vs_ids_mm"], ch["numpy_vs_fresco_ids"]
        out.append(f"Geometry check on {d['frame']}: depth from Fresco's ids vs Fresco's depth "
                   f"PNG: median {d['median']:.2f} mm, max {d['max']:.2f} mm; numpy z-buffer vs "
                   f"Fresco's ids: {a['same_triangle_fraction']:.4f} same triangle, "
                   f"{a['surface_disagreeing_pixels']} pixels differ on surface/none.")
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    main()
