# COLMAP images.txt (world to camera) as TUM lines (camera to world: q inverted, centre =
# -R^T t), frame i (its image name's number) stamped i / fps + off. For the screenshot
# scripts beside it: awk -v fps=30 -v off=0.2 -f ui/doc/tum_from_colmap.awk images.txt
/^#/ || NF < 10 { next }
{ w = $2; x = -$3; y = -$4; z = -$5; tx = $6; ty = $7; tz = $8
  cx = y*tz - z*ty; cy = z*tx - x*tz; cz = x*ty - y*tx
  dx = y*cz - z*cy; dy = z*cx - x*cz; dz = x*cy - y*cx
  n = $10; sub(/\.png$/, "", n)
  printf "%.9f %.12f %.12f %.12f %.15f %.15f %.15f %.15f\n", n / fps + off,
         -(tx + 2*w*cx + 2*dx), -(ty + 2*w*cy + 2*dy), -(tz + 2*w*cz + 2*dz), x, y, z, w }
