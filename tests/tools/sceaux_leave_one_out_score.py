# Scores tests/tools/sceaux_leave_one_out.sh's renders against the left-out photos: PSNR over
# the pixels the render covers, 1 - NCC (9x9 windows, grey, mask eroded by 9x9), coverage.
# Usage: /usr/bin/python3 tests/tools/sceaux_leave_one_out_score.py scene_mesh [scene_mesh_refine]
import os, sys
import cv2
import numpy as np
D=os.environ.get('SCEAUX_DIR', '../shared/data/sceaux-castle-openmvs') + '/images'
def ncc_map(a, b, k=9):
    a=a.astype(np.float64); b=b.astype(np.float64)
    mu_a=cv2.blur(a,(k,k)); mu_b=cv2.blur(b,(k,k))
    va=cv2.blur(a*a,(k,k))-mu_a**2; vb=cv2.blur(b*b,(k,k))-mu_b**2; cov=cv2.blur(a*b,(k,k))-mu_a*mu_b
    return cov/np.sqrt(np.maximum(va*vb,1e-6))
for mesh in sys.argv[1:]:
    rows=[]
    for i in range(10):
        n='%05d'%i
        r=cv2.imread(f'/tmp/loo/{mesh}/{i}/render/{n}.png', cv2.IMREAD_UNCHANGED)
        p=cv2.imread(f'{D}/{n}.jpg')
        m=r[...,3]>0
        d=(r[...,:3].astype(float)-p.astype(float))[m]
        psnr=10*np.log10(255**2/np.mean(d**2))
        ga=cv2.cvtColor(r[...,:3],cv2.COLOR_BGR2GRAY); gb=cv2.cvtColor(p,cv2.COLOR_BGR2GRAY)
        me=cv2.erode(m.astype(np.uint8),np.ones((9,9),np.uint8))>0
        ncc=ncc_map(ga,gb)[me]
        rows.append((psnr,1-np.mean(ncc),m.mean()))
    a=np.array(rows)
    print(mesh, 'PSNR mean %.2f median %.2f worst %.2f | 1-NCC mean %.3f median %.3f worst %.3f | coverage %.3f'%(a[:,0].mean(),np.median(a[:,0]),a[:,0].min(),a[:,1].mean(),np.median(a[:,1]),a[:,1].max(),a[:,2].mean()))
    print('  per photo PSNR', ' '.join('%.1f'%x for x in a[:,0]))
