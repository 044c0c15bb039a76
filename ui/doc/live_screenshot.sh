#!/bin/sh
# Makes ui/doc/live.jpg: the app painting a live capture on loopback. A synthetic capture's
# frames are streamed by `ffmpeg` to udp://127.0.0.1:5000 (H.264, lossless 4:4:4) while a
# tracker serves its true poses as TUM lines on tcp://127.0.0.1:9000 (its clock 0.2 s
# ahead, 30 Hz from when the app opens the stream); `fresco gui --screenshot` paints 90
# frames (the offset estimated first) and writes the window. Run from the repository root
# after building; needs ffmpeg, xvfb-run and python3. Usage: ui/doc/live_screenshot.sh [DIR]
set -e
dir=${1:-/tmp/fresco-live-screenshot}
mkdir -p "$dir"
build/app/fresco synth --scene builtin:cube-room --out "$dir/synth" --frames 300 \
    --size 320x240 --seed 3
# The tracker's poses: synth's true poses (COLMAP images.txt, world to camera) as TUM lines
# (camera to world: q inverted, centre = -R^T t), frame i stamped i / 30 + 0.2 s.
awk -v fps=30 -v off=0.2 -f ui/doc/tum_from_colmap.awk \
    "$dir/synth/truth/images.txt" | sort -n > "$dir/tracker.tum"
cat > "$dir/live.json" <<'EOF'
{"fresco": 1, "scene": "synth/scene.gltf", "camera": "synth/camera.cameramodel",
 "video": "udp://127.0.0.1:5000", "poses": "tcp://127.0.0.1:9000",
 "pipeline": {"texel_size_m": 0.02}, "live": {"estimate_offset": true, "queue_frames": 8}}
EOF
# The tracker (waits for the app's connection, then for it to open the video port).
python3 ui/doc/serve_tum.py "$dir/tracker.tum" 9000 5000 &
sleep 0.5
xvfb-run -a -s "-screen 0 1600x1000x24" build/app/fresco gui "$dir/live.json" \
    --screenshot "$dir/live.png" --frames 90 &
gui=$!
while ! grep -q ":1388 " /proc/net/udp; do sleep 0.2; done
ffmpeg -hide_banner -loglevel error -re -framerate 30 -i "$dir/synth/frames/%06d.png" \
    -c:v libx264 -qp 0 -pix_fmt yuv444p -tune zerolatency -g 15 -f mpegts \
    'udp://127.0.0.1:5000?pkt_size=1316'
wait $gui
ffmpeg -hide_banner -loglevel error -y -i "$dir/live.png" -q:v 10 ui/doc/live.jpg
