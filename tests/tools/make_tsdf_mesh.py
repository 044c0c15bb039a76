#!/usr/bin/env python3
"""Make a TSDF-fused mesh of a `fresco synth` capture, as a depth sensor would.

A measurement tool only (docs/results.md, "Photogrammetry and scanned meshes"): neither
Fresco's build nor its tests need it. It needs Open3D (Debian: python3-open3d).

For each frame of the capture the scene (DIR/scene.gltf, written without movers) is
ray-cast at the frame's true pose (DIR/truth/images.txt, COLMAP world-to-camera) through
the capture's pinhole camera (DIR/sparse/cameras.txt); Gaussian depth noise that grows
with depth squared is added (sigma = --noise-mm at 1 m, as structured-light sensors
have: about 1.4 mm at 1 m, 6 mm at 2 m, 13 mm at 3 m for a Kinect v1), and the noisy
depth with the frame's colours is fused into Open3D's ScalableTSDFVolume. The marching
cubes mesh is written as binary PLY in the scene's world frame, with its vertex colours
and normals as extracted: no smoothing, no decimation.

Pixel centres: COLMAP's pixel (0,0) is at (0.5,0.5); Fresco's and Open3D's (its TSDF
integration rounds x*fx/z + cx) at (0,0), so cx and cy are COLMAP's less 0.5.

Deterministic for the same capture and options (--seed).

    /usr/bin/python3 tests/tools/make_tsdf_mesh.py CAPTURE_DIR --voxel 0.02 --out MESH.ply
"""

import argparse
import json
import os
import sys
import time


def fail(msg, code=2):
    print(f"make_tsdf_mesh: {msg}", file=sys.stderr)
    sys.exit(code)


try:
    import numpy as np
    import open3d as o3d
except ImportError as e:  # a measurement tool: say what is missing, exit clearly
    fail(f"needs Open3D and NumPy ({e}); on Debian: apt-get install python3-open3d")


def read_camera(path):
    """COLMAP cameras.txt with one PINHOLE or SIMPLE_PINHOLE camera: (w, h, fx, fy, cx, cy)
    in Fresco's/Open3D's pixel convention (centre of pixel (0,0) at (0,0))."""
    cams = {}
    with open(path) as f:
        for line in f:
            if not line.strip() or line.startswith("#"):
                continue
            p = line.split()
            model, w, h = p[1], int(p[2]), int(p[3])
            v = [float(x) for x in p[4:]]
            if model == "PINHOLE":
                fx, fy, cx, cy = v[:4]
            elif model == "SIMPLE_PINHOLE":
                fx, cx, cy = v[:3]
                fy = fx
            else:
                fail(f"{path}: camera model {model} is not a pinhole; make the capture "
                     "with --lens pinhole")
            cams[int(p[0])] = (w, h, fx, fy, cx - 0.5, cy - 0.5)
    if len(cams) != 1:
        fail(f"{path}: expected one camera, found {len(cams)}")
    return next(iter(cams.values()))


def quat_to_rot(qw, qx, qy, qz):
    n = np.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
    qw, qx, qy, qz = qw / n, qx / n, qy / n, qz / n
    return np.array([
        [1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
        [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
        [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)],
    ])


def read_images(path):
    """COLMAP images.txt: [(name, 4x4 world-to-camera)] in file order."""
    out = []
    with open(path) as f:
        lines = [l for l in f if not l.startswith("#")]
    i = 0
    while i < len(lines):
        p = lines[i].split()
        if not p:
            i += 1
            continue
        q = [float(x) for x in p[1:5]]
        t = np.array([float(x) for x in p[5:8]])
        T = np.eye(4)
        T[:3, :3] = quat_to_rot(*q)
        T[:3, 3] = t
        out.append((p[9], T))
        i += 2  # the POINTS2D line follows (possibly empty)
    return out


def cast_rays(tris, origin, dirs):
    """Nearest hit of rays from one origin, in units of each direction's length (inf for
    none); both faces. Brute force over the triangles (Moller-Trumbore, float64): the
    synth scenes have tens to thousands of triangles. Open3D's RaycastingScene is not
    used: with Debian's Embree (built with ray masks) it reports no hit at all."""
    t_best = np.full(len(dirs), np.inf)
    for a, b, c in tris:
        e1, e2 = b - a, c - a
        p = np.cross(dirs, e2)
        det = p @ e1
        ok = np.abs(det) > 1e-12
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        s = origin - a
        u = (p @ s) * inv
        q = np.cross(s, e1)
        v = (dirs @ q) * inv
        t = (q @ e2) * inv
        hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-9) & (t < t_best)
        t_best[hit] = t[hit]
    return t_best


def normal_error_deg(tris, points, normals):
    """Angle between each face normal and the normal of the scene triangle under its
    centroid (the one of least plane distance among those whose prism holds the point,
    with a small margin; else of least plane distance), degrees, sign ignored."""
    best_d = np.full(len(points), np.inf)
    best_any = np.full(len(points), np.inf)
    err = np.zeros(len(points))
    err_any = np.zeros(len(points))
    for a, b, c in tris:
        n = np.cross(b - a, c - a)
        area2 = np.linalg.norm(n)
        if area2 < 1e-12:
            continue
        n /= area2
        dist = np.abs((points - a) @ n)
        # barycentrics of the projection, relative to the triangle's size
        w_a = (np.cross(c - b, points - b) @ n) / area2
        w_b = (np.cross(a - c, points - c) @ n) / area2
        w_c = 1.0 - w_a - w_b
        inside = (w_a > -0.02) & (w_b > -0.02) & (w_c > -0.02)
        ang = np.degrees(np.arccos(np.clip(np.abs(normals @ n), 0.0, 1.0)))
        take = inside & (dist < best_d)
        best_d[take] = dist[take]
        err[take] = ang[take]
        take = dist < best_any
        best_any[take] = dist[take]
        err_any[take] = ang[take]
    return np.where(np.isfinite(best_d), err, err_any)


def write_project(src, dst, mesh):
    """A copy of the capture's project file `src` at `dst` with `scene` = `mesh`, every
    relative path rebased onto dst's folder."""
    with open(src) as f:
        proj = json.load(f)
    src_dir = os.path.dirname(os.path.abspath(src))
    dst_dir = os.path.dirname(os.path.abspath(dst))

    def rebase(p):
        if not isinstance(p, str) or os.path.isabs(p) or ":" in p:
            return p
        r = os.path.relpath(os.path.join(src_dir, p), dst_dir)
        return r + "/" if p.endswith("/") and not r.endswith("/") else r

    for key in ("camera", "video", "poses"):
        if key in proj:
            proj[key] = rebase(proj[key])
    if isinstance(proj.get("truth"), dict) and "poses" in proj["truth"]:
        proj["truth"]["poses"] = rebase(proj["truth"]["poses"])
    proj["scene"] = os.path.relpath(os.path.abspath(mesh), dst_dir)
    with open(dst, "w") as f:
        json.dump(proj, f, indent=2)
        f.write("\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("capture", help="a `fresco synth` output folder")
    ap.add_argument("--out", required=True, help="the PLY to write")
    ap.add_argument("--voxel", type=float, default=0.02, help="TSDF voxel, metres (0.02)")
    ap.add_argument("--trunc", type=float, default=0.0,
                    help="TSDF truncation, metres (default 4 voxels)")
    ap.add_argument("--noise-mm", type=float, default=1.5,
                    help="depth noise sigma at 1 m, mm; grows with depth squared (1.5)")
    ap.add_argument("--max-depth", type=float, default=8.0,
                    help="depth readings farther than this are dropped, metres (8)")
    ap.add_argument("--frames", type=int, default=0, help="use the first N frames (all)")
    ap.add_argument("--seed", type=int, default=1, help="noise seed (1)")
    ap.add_argument("--project", default="",
                    help="also write this project file: the capture's project.json with "
                         "the mesh as its scene (paths relative to the new file's folder)")
    a = ap.parse_args()

    d = a.capture
    scene_path = os.path.join(d, "scene.gltf")
    cams_path = os.path.join(d, "sparse", "cameras.txt")
    poses_path = os.path.join(d, "truth", "images.txt")
    for p in (scene_path, cams_path, poses_path):
        if not os.path.isfile(p):
            fail(f"{p}: not found (is {d} a `fresco synth` capture?)")
    w, h, fx, fy, cx, cy = read_camera(cams_path)
    poses = read_images(poses_path)
    if a.frames > 0:
        poses = poses[:a.frames]
    trunc = a.trunc if a.trunc > 0 else 4.0 * a.voxel

    scene = o3d.io.read_triangle_mesh(scene_path)
    if len(scene.triangles) == 0:
        fail(f"{scene_path}: no triangles read")
    tris = np.asarray(scene.vertices)[np.asarray(scene.triangles)]  # (T, 3, 3)

    # Camera-frame ray directions with z = 1, so that t_hit is the camera z (depth).
    u, v = np.meshgrid(np.arange(w, dtype=np.float64), np.arange(h, dtype=np.float64))
    dirs_cam = np.stack([(u - cx) / fx, (v - cy) / fy, np.ones_like(u)], axis=-1)

    intr = o3d.camera.PinholeCameraIntrinsic(w, h, fx, fy, cx, cy)
    vol = o3d.pipelines.integration.ScalableTSDFVolume(
        voxel_length=a.voxel, sdf_trunc=trunc,
        color_type=o3d.pipelines.integration.TSDFVolumeColorType.RGB8)
    rng = np.random.default_rng(a.seed)
    t0 = time.time()
    zs = []
    for name, T in poses:
        R, t = T[:3, :3], T[:3, 3]
        origin = -R.T @ t
        dw = dirs_cam.reshape(-1, 3) @ R  # R^T d for every row d
        z = cast_rays(tris, origin, dw).reshape(h, w)
        ok = np.isfinite(z) & (z > 0) & (z <= a.max_depth)
        z = np.where(ok, z, 0.0)
        zs.append(z[ok])
        noisy = z + rng.standard_normal(z.shape) * (a.noise_mm * 1e-3) * z * z
        noisy = np.where(ok & (noisy > 0), noisy, 0.0).astype(np.float32)
        img_path = os.path.join(d, "frames", os.path.splitext(name)[0] + ".png")
        color = o3d.io.read_image(img_path)
        if np.asarray(color).shape[:2] != (h, w):
            fail(f"{img_path}: not {w}x{h}")
        if np.asarray(color).ndim == 3 and np.asarray(color).shape[2] == 4:
            color = o3d.geometry.Image(np.ascontiguousarray(np.asarray(color)[:, :, :3]))
        rgbd = o3d.geometry.RGBDImage.create_from_color_and_depth(
            color, o3d.geometry.Image(noisy), depth_scale=1.0,
            depth_trunc=a.max_depth, convert_rgb_to_intensity=False)
        vol.integrate(rgbd, intr, T)
    zall = np.concatenate(zs)
    mesh = vol.extract_triangle_mesh()
    mesh.compute_vertex_normals()  # per-vertex, from the triangles as they are: no smoothing
    if not o3d.io.write_triangle_mesh(a.out, mesh, write_ascii=False):
        fail(f"{a.out}: could not write")
    tri = np.asarray(mesh.triangles)
    vtx = np.asarray(mesh.vertices)
    fn = np.cross(vtx[tri[:, 1]] - vtx[tri[:, 0]], vtx[tri[:, 2]] - vtx[tri[:, 0]])
    fn /= np.maximum(np.linalg.norm(fn, axis=1, keepdims=True), 1e-30)
    dev = normal_error_deg(tris, vtx[tri].mean(axis=1), fn)
    if a.project:
        write_project(os.path.join(d, "project.json"), a.project, a.out)
    print(f"{a.out}: {len(tri)} triangles, {len(vtx)} vertices; {len(poses)} frames "
          f"{w}x{h}, voxel {a.voxel * 100:g} cm, trunc {trunc * 100:g} cm, noise "
          f"{a.noise_mm:g} mm at 1 m (depth {np.percentile(zall, 5):.2f}-"
          f"{np.percentile(zall, 95):.2f} m, 5-95 %); face normal against the scene's: median "
          f"{np.median(dev):.1f} deg, 90 % {np.percentile(dev, 90):.1f} deg; "
          f"{time.time() - t0:.1f} s")


if __name__ == "__main__":
    main()
