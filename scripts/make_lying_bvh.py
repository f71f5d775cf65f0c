"""A BVH whose rest lies along +x, as Bandai-Namco's files do: every OFFSET below `Hips` (and
every position channel below it) turned by Rz(-90 deg), each joint's rotation conjugated to
match, and `Hips`' rotation turned back upright, so every joint stands in every frame where
it stood in the input; `joint_Root` is left as it is. Rotation channels must be
`Xrotation Yrotation Zrotation`.

    python3 scripts/make_lying_bvh.py tests/data/rigs/bandai_walk.bvh tests/data/rigs/bandai_lying_walk.bvh
"""
import numpy as np, re, sys
src = open(sys.argv[1]).read()
hier, motion = src.split("MOTION")
Q = np.array([[0,1,0],[-1,0,0],[0,0,1]], float)  # Rz(-90): +y -> +x
def rx(a): c,s=np.cos(a),np.sin(a); return np.array([[1,0,0],[0,c,-s],[0,s,c]])
def ry(a): c,s=np.cos(a),np.sin(a); return np.array([[c,0,s],[0,1,0],[-s,0,c]])
def rz(a): c,s=np.cos(a),np.sin(a); return np.array([[c,-s,0],[s,c,0],[0,0,1]])
R = {'X': rx, 'Y': ry, 'Z': rz}
def decompose_xyz(M):
    b = np.arcsin(np.clip(M[0,2], -1, 1)); a = np.arctan2(-M[1,2], M[2,2]); c = np.arctan2(-M[0,1], M[0,0]); return np.degrees([a,b,c])
out_lines = []; joints = []  # (is_root, channels)
lines = hier.splitlines()
offsets_seen = 0
for line in lines:
    t = line.split()
    if t and t[0] == 'OFFSET':
        offsets_seen += 1
    if t and t[0] == 'OFFSET' and offsets_seen > 2:
        o = Q @ np.array(list(map(float, t[1:4])))
        line = line[:len(line)-len(line.lstrip())] + 'OFFSET %.6f %.6f %.6f' % tuple(o)
    if t and t[0] == 'CHANNELS':
        joints.append(t[2:])
    out_lines.append(line)
mlines = [l for l in motion.strip().splitlines()]
header, frames = mlines[:2], mlines[2:]
new_frames = []
for f in frames:
    v = list(map(float, f.split())); k = 0; out = []
    for j, ch in enumerate(joints):
        vals = dict(zip(ch, v[k:k+len(ch)])); k += len(ch)
        order = [c[0] for c in ch if c.endswith('rotation')]
        assert order == ['X','Y','Z'], order
        M = np.eye(3)
        for c in order: M = M @ R[c](np.radians(vals[c + 'rotation']))
        M2 = M if j == 0 else (M @ Q.T if j == 1 else Q @ M @ Q.T)
        a, b, c = decompose_xyz(M2)
        p = np.array([vals.get('Xposition', 0), vals.get('Yposition', 0), vals.get('Zposition', 0)])
        if j > 1: p = Q @ p
        for c_name in ch:
            if c_name.endswith('position'): out.append(p['XYZ'.index(c_name[0])])
            else: out.append({'X': a, 'Y': b, 'Z': c}[c_name[0]])
    new_frames.append(' '.join('%.6f' % x for x in out))
open(sys.argv[2], 'w').write('\n'.join(out_lines) + '\nMOTION\n' + '\n'.join(header) + '\n' + '\n'.join(new_frames) + '\n')
