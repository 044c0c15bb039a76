#!/usr/bin/env python3
"""Seed corpora for the fuzz targets from the real files Fresco reads.

Usage: seed_corpora.py SOURCE_DIR SHARED_DATA_DIR OUT_DIR

Writes OUT_DIR/<target>/ for each fuzz target of tests/fuzz from SOURCE_DIR/projects,
SOURCE_DIR/tests/fuzz/seeds/<target> (hand-written edge cases and past findings) and, when
it exists, SHARED_DATA_DIR (../shared/data). A fuzz input is one file, so glTF seeds are
made self-contained: buffers and small images become data URIs (images over 16 KB become a
2x2 PNG, to keep inputs small), and single-buffer scenes are also packed as GLB. Seeds over
64 KB (the fuzzers' -max_len) are left out.
"""
import base64
import glob
import json
import os
import shutil
import struct
import sys
import zlib

MAX_IMAGE_BYTES = 16 * 1024
MAX_SEED_BYTES = 64 * 1024  # the fuzzers' -max_len: bigger seeds would only be truncated


def tiny_png():
    """A 2x2 RGBA PNG (red, green / blue, white)."""
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)
    rows = b"\0\xff\0\0\xff\0\xff\0\xff" + b"\0\0\0\xff\xff\xff\xff\xff\xff"
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 2, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def data_uri(mime, data):
    return "data:%s;base64,%s" % (mime, base64.b64encode(data).decode("ascii"))


def embedded_gltf(path):
    """The glTF at `path` with every buffer and image as a data URI (None if unreadable)."""
    folder = os.path.dirname(path)
    try:
        with open(path, encoding="utf-8") as f:
            gltf = json.load(f)
    except (OSError, ValueError):
        return None, None
    buffers = []
    for buffer in gltf.get("buffers", []):
        uri = buffer.get("uri", "")
        if uri.startswith("data:") or not uri:
            buffers.append(None)
            continue
        try:
            with open(os.path.join(folder, uri), "rb") as f:
                data = f.read()
        except OSError:
            return None, None
        buffers.append(data)
        buffer["uri"] = data_uri("application/octet-stream", data)
    for image in gltf.get("images", []):
        uri = image.get("uri", "")
        if not uri or uri.startswith("data:"):
            continue
        data = None
        image_path = os.path.join(folder, uri)
        if os.path.isfile(image_path) and os.path.getsize(image_path) <= MAX_IMAGE_BYTES:
            with open(image_path, "rb") as f:
                data = f.read()
        mime = "image/jpeg" if uri.lower().endswith((".jpg", ".jpeg")) and data else "image/png"
        image["uri"] = data_uri(mime, data if data else tiny_png())
    return gltf, buffers


def glb(gltf, buffers):
    """GLB (JSON chunk + BIN chunk) of a single-buffer glTF, or None."""
    if len(buffers) != 1 or buffers[0] is None:
        return None
    gltf = json.loads(json.dumps(gltf))
    del gltf["buffers"][0]["uri"]
    text = json.dumps(gltf, separators=(",", ":")).encode("utf-8")
    text += b" " * (-len(text) % 4)
    binary = buffers[0] + b"\0" * (-len(buffers[0]) % 4)
    body = (struct.pack("<I", len(text)) + b"JSON" + text +
            struct.pack("<I", len(binary)) + b"BIN\0" + binary)
    return b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body


def main():
    source, shared, out = sys.argv[1:4]
    have_shared = os.path.isdir(shared)
    patterns = {
        "project": ["projects/*/*.json"],
        "colmap_text": ["projects/**/cameras.txt", "projects/**/images.txt",
                        "projects/**/points3D.txt"],
        "tum": ["projects/**/*.tum"],
        "cameramodel": ["projects/**/*.cameramodel"],
        "board_spec": [],
        "gltf": ["projects/**/*.glb"],
    }
    shared_patterns = {
        "colmap_text": ["*/*/cameras.txt", "*/*/images.txt", "*/*/points3D.txt"],
        "cameramodel": ["*/*.cameramodel"],
        "gltf": ["gltf/*/glTF-Binary/*.glb"],
    }
    gltf_sources = glob.glob(os.path.join(source, "projects/**/*.gltf"), recursive=True)
    if have_shared:
        gltf_sources += glob.glob(os.path.join(shared, "gltf/*/glTF/*.gltf"))
    counts = {}
    for target, globs in patterns.items():
        folder = os.path.join(out, target)
        shutil.rmtree(folder, ignore_errors=True)
        os.makedirs(folder)
        files = []
        for pattern in globs:
            files += glob.glob(os.path.join(source, pattern), recursive=True)
        if have_shared:
            for pattern in shared_patterns.get(target, []):
                files += glob.glob(os.path.join(shared, pattern))
        files += glob.glob(os.path.join(source, "tests/fuzz/seeds", target, "*"))
        for path in sorted(set(files)):
            name = os.path.relpath(path, source if path.startswith(source) else shared)
            shutil.copyfile(path, os.path.join(folder, name.replace(os.sep, "__")))
        if target == "gltf":
            for path in sorted(gltf_sources):
                gltf, buffers = embedded_gltf(path)
                if gltf is None:
                    continue
                stem = os.path.basename(path)[:-len(".gltf")]
                with open(os.path.join(folder, stem + ".embedded.gltf"), "w") as f:
                    json.dump(gltf, f, separators=(",", ":"))
                packed = glb(gltf, buffers)
                if packed:
                    with open(os.path.join(folder, stem + ".packed.glb"), "wb") as f:
                        f.write(packed)
        for name in os.listdir(folder):
            if os.path.getsize(os.path.join(folder, name)) > MAX_SEED_BYTES:
                os.remove(os.path.join(folder, name))
        counts[target] = len(os.listdir(folder))
    print("seed corpora in %s (%s): %s" % (out, "with ../shared/data" if have_shared else
                                          "no ../shared/data",
                                          ", ".join("%s %d" % kv for kv in counts.items())))


if __name__ == "__main__":
    main()
