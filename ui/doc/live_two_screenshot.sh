#!/bin/sh
# Makes docs/images/two-live-streams-app.jpg: the app painting two live cameras into one
# model on loopback. Two synthetic captures of the room (seeds 3 and 8) are streamed by
# `ffmpeg` to udp://127.0.0.1:5000 and :5001 while two trackers serve their true poses as TUM
# lines on tcp://127.0.0.1:9000 and :9001 (0.2 s ahead, as each stream's time_offset_s says);
# `fresco gui --screenshot` paints 160 frames of both and writes the window. Run from the
# repository root after building; needs ffmpeg, xvfb-run and python3.
# Usage: ui/doc/live_two_screenshot.sh [DIR]
set -e
dir=${1:-/tmp/fresco-live-two-screenshot}
mkdir -p "$dir"
for s in 0 1; do
  build/app/fresco synth --scene builtin:cube-room --out "$dir/synth$s" --frames 300 \
      --size 320x240 --seed $((3 + 5 * s)) >/dev/null
  # COLMAP images.txt (world to camera) as TUM lines (camera to world), frame i at i/30+0.2 s.
  awk -v fps=30 -v off=0.2 -f ui/doc/tum_from_colmap.awk \
      "$dir/synth$s/truth/images.txt" | sort -n > "$dir/tracker$s.tum"
done
cat > "$dir/live.json" <<'EOF'
{"fresco": 2, "scene": "synth0/scene.gltf",
 "streams": [
  {"camera": "synth0/camera.cameramodel", "video": "udp://127.0.0.1:5000",
   "poses": "tcp://127.0.0.1:9000", "time_offset_s": 0.2},
  {"camera": "synth1/camera.cameramodel", "video": "udp://127.0.0.1:5001",
   "poses": "tcp://127.0.0.1:9001", "time_offset_s": 0.2}],
 "pipeline": {"texel_size_m": 0.02}, "live": {"queue_frames": 8}}
EOF
# The trackers (each waits for the app's connection, then for its video port to open).
for s in 0 1; do
  python3 ui/doc/serve_tum.py "$dir/tracker$s.tum" $((9000 + s)) $((5000 + s)) &
done
sleep 0.5
xvfb-run -a -s "-screen 0 1600x1000x24" build/app/fresco gui "$dir/live.json" \
    --screenshot "$dir/live.png" --frames 160 &
gui=$!
for s in 0 1; do
  (port=$(printf ':%04X ' $((5000 + s)))
   while ! grep -q "$port" /proc/net/udp; do sleep 0.2; done
   ffmpeg -hide_banner -loglevel error -re -framerate 30 -i "$dir/synth$s/frames/%06d.png" \
       -c:v libx264 -qp 0 -pix_fmt yuv444p -tune zerolatency -g 15 -f mpegts \
       "udp://127.0.0.1:$((5000 + s))?pkt_size=1316" || true) &
done
wait $gui
ffmpeg -hide_banner -loglevel error -y -i "$dir/live.png" -q:v 10 docs/images/two-live-streams-app.jpg
