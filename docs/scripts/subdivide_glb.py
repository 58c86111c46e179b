"""Split every triangle of a one-primitive GLB into four at its edges' midpoints,
LEVELS times: the same surface (positions, UVs linear; normals interpolated and
renormalised, as the rasteriser does), more vertices, so the per-vertex
transfer is sampled more densely (docs/records/2026-11-26-path-tracer-cycles.md, "What the numbers point to").

    python3 docs/scripts/subdivide_glb.py IN.glb OUT.glb LEVELS   # numpy
"""
import json, os, struct, sys
import numpy as np

if len(sys.argv) != 4 or not sys.argv[3].isdigit() or not 0 < int(sys.argv[3]) <= 3:
    sys.exit("usage: subdivide_glb.py IN.glb OUT.glb LEVELS (1 to 3)")
src, dst, levels = sys.argv[1], sys.argv[2], int(sys.argv[3])
if not os.path.isdir(os.path.dirname(os.path.abspath(dst))):
    sys.exit(f"{dst}: no such folder")
try:
    b = open(src, 'rb').read()
except OSError as e:
    sys.exit(f"{src}: {e.strerror}")
if len(b) < 20 or b[:4] != b'glTF':
    sys.exit(f"{src}: not a binary glTF (GLB)")
jl, _ = struct.unpack('<II', b[12:20]); j = json.loads(b[20:20 + jl])
bin_off = 20 + jl; bl, _ = struct.unpack('<II', b[bin_off:bin_off + 8]); binary = b[bin_off + 8:bin_off + 8 + bl]
# What the rewrite below keeps: one mesh of one indexed triangle primitive with
# exactly these attributes, tightly packed.
prims = [q for m in j.get('meshes', []) for q in m['primitives']]
if len(prims) != 1 or prims[0].get('mode', 4) != 4 or 'indices' not in prims[0]:
    sys.exit(f"{src}: needs one mesh of one indexed triangle primitive")
if set(prims[0]['attributes']) != {'POSITION', 'NORMAL', 'TEXCOORD_0'}:
    sys.exit(f"{src}: needs exactly POSITION, NORMAL and TEXCOORD_0, has {sorted(prims[0]['attributes'])}")
if any('byteStride' in v for v in j['bufferViews']):
    sys.exit(f"{src}: interleaved buffer views are not handled")
def acc(i):
    a = j['accessors'][i]; v = j['bufferViews'][a['bufferView']]
    dt = {5123: np.uint16, 5125: np.uint32, 5126: np.float32}[a['componentType']]
    n = {'SCALAR': 1, 'VEC2': 2, 'VEC3': 3}[a['type']]
    off = v.get('byteOffset', 0) + a.get('byteOffset', 0)
    return np.frombuffer(binary, dt, a['count'] * n, off).reshape(a['count'], n).copy()
prim = j['meshes'][0]['primitives'][0]
idx = acc(prim['indices']).reshape(-1, 3).astype(np.int64)
pos = acc(prim['attributes']['POSITION']).astype(np.float64)
nor = acc(prim['attributes']['NORMAL']).astype(np.float64)
uv = acc(prim['attributes']['TEXCOORD_0']).astype(np.float64)
for _ in range(levels):
    e = np.concatenate([idx[:, [0, 1]], idx[:, [1, 2]], idx[:, [2, 0]]])
    key = np.sort(e, 1)
    uniq, inv = np.unique(key, axis=0, return_inverse=True)
    mid = len(pos) + np.arange(len(uniq))
    pos = np.concatenate([pos, (pos[uniq[:, 0]] + pos[uniq[:, 1]]) / 2])
    n = nor[uniq[:, 0]] + nor[uniq[:, 1]]; n /= np.linalg.norm(n, axis=1, keepdims=True)
    nor = np.concatenate([nor, n])
    uv = np.concatenate([uv, (uv[uniq[:, 0]] + uv[uniq[:, 1]]) / 2])
    t = len(idx); m = mid[inv.ravel()]
    m01, m12, m20 = m[:t], m[t:2 * t], m[2 * t:]
    a, b_, c = idx[:, 0], idx[:, 1], idx[:, 2]
    idx = np.concatenate([np.stack([a, m01, m20], 1), np.stack([m01, b_, m12], 1),
                          np.stack([m20, m12, c], 1), np.stack([m01, m12, m20], 1)])
chunks = [idx.astype(np.uint32).ravel().tobytes(), pos.astype(np.float32).tobytes(),
          nor.astype(np.float32).tobytes(), uv.astype(np.float32).tobytes()]
views, off, blob = [], 0, b''
for c in chunks:
    views.append({'buffer': 0, 'byteOffset': off, 'byteLength': len(c)}); blob += c; off += len(c)
    pad = (-len(blob)) % 4; blob += b'\0' * pad; off += pad
j['bufferViews'] = views; j['buffers'] = [{'byteLength': len(blob)}]
A = j['accessors']
A[prim['indices']].update(bufferView=0, componentType=5125, count=int(idx.size), max=[int(idx.max())], min=[0])
for k, view, arr in (('POSITION', 1, pos), ('NORMAL', 2, nor), ('TEXCOORD_0', 3, uv)):
    a = A[prim['attributes'][k]]; a.update(bufferView=view, count=len(arr))
    a['max'] = [float(x) for x in arr.max(0).astype(np.float32)]; a['min'] = [float(x) for x in arr.min(0).astype(np.float32)]
    a.pop('byteOffset', None)
A[prim['indices']].pop('byteOffset', None)
js = json.dumps(j).encode(); js += b' ' * ((-len(js)) % 4)
out = struct.pack('<III', 0x46546C67, 2, 12 + 8 + len(js) + 8 + len(blob)) + struct.pack('<II', len(js), 0x4E4F534A) + js + struct.pack('<II', len(blob), 0x004E4942) + blob
tmp = dst + '.tmp'
with open(tmp, 'wb') as f:
    f.write(out)
os.replace(tmp, dst)
print(f"{dst}: {len(pos)} vertices, {len(idx)} triangles")
