#!/bin/bash
# Leave-one-out on the Sceaux castle photos (virtual rephotography): each of the 10 photos
# left out in turn, the mesh painted from the other 9 with the defaults, the painted model
# rendered at the left-out photo's pose into /tmp/loo/MESH/I/render/. Score with
# tests/tools/sceaux_leave_one_out_score.py MESH.
# Usage (from the repository root, ../shared beside it):
#   bash tests/tools/sceaux_leave_one_out.sh scene_mesh        # or scene_mesh_refine
set -e
D=${SCEAUX_DIR:-../shared/data/sceaux-castle-openmvs}
D=$(cd "$D" && pwd)
F=$(pwd)/build/app/fresco
mesh=$1   # scene_mesh or scene_mesh_refine
[ -n "$mesh" ] || { echo "usage: $0 scene_mesh|scene_mesh_refine" >&2; exit 2; }
for i in 0 1 2 3 4 5 6 7 8 9; do
  n=$(printf "%05d.jpg" $i)
  w=/tmp/loo/$mesh/$i; rm -rf $w; mkdir -p $w/frames
  for f in $D/images/*.jpg; do [ "$(basename $f)" != "$n" ] && ln -s $f $w/frames/; done
  /usr/bin/python3 - "$D/colmap_sparse_txt/images.txt" "$n" "$w" <<'PY'
import sys
src,name,w=sys.argv[1:]
lines=open(src).read().split('\n'); keep=[];only=[]
i=0
while i<len(lines):
    l=lines[i]
    if l.startswith('#') or not l.strip(): i+=1; continue
    pair=[l, lines[i+1] if i+1<len(lines) else '']
    (only if pair[0].split()[-1]==name else keep).extend(pair); i+=2
open(w+'/train.txt','w').write('\n'.join(keep)+'\n'); open(w+'/test.txt','w').write('\n'.join(only)+'\n')
PY
  echo "{\"fresco\": 1, \"scene\": \"$D/openmvs_original/$mesh.ply\", \"camera\": \"$D/colmap_sparse_txt/cameras.txt\", \"video\": \"$w/frames\", \"poses\": \"$w/train.txt\"}" > $w/p.json
  $F run $w/p.json --out $w/out --quiet
  $F render $w/out/painted.gltf --camera $D/colmap_sparse_txt/cameras.txt --poses $w/test.txt --out $w/render > /dev/null 2>&1
done
