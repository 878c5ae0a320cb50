#!/usr/bin/python3
"""make_gem.py — writes the assets of scenes/gem_asset.yaml: a glTF 2.0 scene and a PLY mesh, small and
made from primitives, so that the repository holds no file it cannot regenerate.

Usage: /usr/bin/python3 tools/make_gem.py [OUTDIR]      (default: scenes/gem next to this tool)

  gem.gltf   JSON with its one buffer embedded (a base64 data: URI). Three meshes, each with its material
             (glTF's metallic-roughness model; murk maps it to ggx, README "Assets"):
               gem     an eight-faceted gem (a square bipyramid), copper: base colour (0.95, 0.45, 0.25),
                       metallic 1, roughness 0.3; turned 30 degrees about y by its node
               plinth  a box under it, marble: base colour 0.8, metallic 0, roughness 0.5
               ember   a small flat square above the gem, facing down, with emissive factor (1, 0.6, 0.3)
             a perspective camera node "view" (yfov 0.6 rad) looking at the gem from the front and above,
             and a KHR_lights_punctual spot light "lamp" above and to the left, aimed at the gem.
  gem.ply    the same gem as an ASCII PLY (no material: the scene gives it one).

Every mesh is closed where it bounds a solid and wound outwards (counter-clockwise seen from outside).
Only the standard library is used and every number is printed with a fixed format, so every run writes
the same bytes (tests/test_assets.c checks this against the committed files).
"""
import base64
import json
import math
import os
import struct
import sys

# The gem: a square bipyramid, tips on the y axis.
GEM_V = [(0.0, 0.0, 0.0), (0.25, 0.3, 0.0), (0.0, 0.3, 0.25), (-0.25, 0.3, 0.0), (0.0, 0.3, -0.25),
         (0.0, 0.55, 0.0)]
GEM_F = [(0, 1, 2), (0, 2, 3), (0, 3, 4), (0, 4, 1), (5, 2, 1), (5, 3, 2), (5, 4, 3), (5, 1, 4)]


def box(lo, hi):
    """A closed box from lo to hi: 8 vertices, 12 triangles wound outwards."""
    v = [(x, y, z) for z in (lo[2], hi[2]) for y in (lo[1], hi[1]) for x in (lo[0], hi[0])]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    f = []
    for a, b, c, d in quads:
        f += [(a, b, c), (a, c, d)]
    return v, f


PLINTH_V, PLINTH_F = box((-0.3, -0.4, -0.3), (0.3, 0.0, 0.3))
# the ember: a square at y = 0.9 facing down (-y)
EMBER_V = [(-0.1, 0.9, -0.1), (0.1, 0.9, -0.1), (0.1, 0.9, 0.1), (-0.1, 0.9, 0.1)]
EMBER_F = [(0, 1, 2), (0, 2, 3)]


def fmt(x):
    return float('%.6f' % x)


def quat_look(eye, target):
    """The rotation (x, y, z, w) turning a glTF camera (looking down -z, +y up) to look from eye to target."""
    fx, fy, fz = (target[i] - eye[i] for i in range(3))
    yaw = math.atan2(-fx, -fz)
    pitch = math.atan2(fy, math.hypot(fx, fz))
    qy = (0.0, math.sin(yaw / 2), 0.0, math.cos(yaw / 2))
    qx = (math.sin(pitch / 2), 0.0, 0.0, math.cos(pitch / 2))
    x1, y1, z1, w1 = qy
    x2, y2, z2, w2 = qx
    return [fmt(w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2), fmt(w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2),
            fmt(w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2), fmt(w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2)]


def gltf():
    blob = b''
    views, accessors, meshes = [], [], []
    for mi, (name, v, f) in enumerate((('gem', GEM_V, GEM_F), ('plinth', PLINTH_V, PLINTH_F),
                                       ('ember', EMBER_V, EMBER_F))):
        pos = struct.pack('<%df' % (3 * len(v)), *[c for p in v for c in p])
        idx = struct.pack('<%dH' % (3 * len(f)), *[i for t in f for i in t])
        idx += b'\0' * (-len(idx) % 4)
        lo = [fmt(min(p[a] for p in v)) for a in range(3)]
        hi = [fmt(max(p[a] for p in v)) for a in range(3)]
        views.append({'buffer': 0, 'byteOffset': len(blob), 'byteLength': len(pos)})
        blob += pos
        views.append({'buffer': 0, 'byteOffset': len(blob), 'byteLength': 6 * len(f)})
        blob += idx
        accessors.append({'bufferView': 2 * mi, 'componentType': 5126, 'count': len(v), 'type': 'VEC3',
                          'min': lo, 'max': hi})
        accessors.append({'bufferView': 2 * mi + 1, 'componentType': 5123, 'count': 3 * len(f), 'type': 'SCALAR'})
        meshes.append({'name': name, 'primitives': [{'attributes': {'POSITION': 2 * mi}, 'indices': 2 * mi + 1,
                                                     'material': mi}]})
    materials = [
        {'name': 'copper', 'pbrMetallicRoughness': {'baseColorFactor': [0.95, 0.45, 0.25, 1.0],
                                                    'metallicFactor': 1.0, 'roughnessFactor': 0.3}},
        {'name': 'marble', 'pbrMetallicRoughness': {'baseColorFactor': [0.8, 0.8, 0.8, 1.0],
                                                    'metallicFactor': 0.0, 'roughnessFactor': 0.5}},
        {'name': 'ember', 'pbrMetallicRoughness': {'baseColorFactor': [0.1, 0.1, 0.1, 1.0],
                                                   'metallicFactor': 0.0, 'roughnessFactor': 1.0},
         'emissiveFactor': [1.0, 0.6, 0.3]},
    ]
    eye, target = (0.0, 0.75, 2.2), (0.0, 0.2, 0.0)
    lamp, aim = (-0.8, 1.4, 0.6), (0.0, 0.25, 0.0)
    nodes = [
        {'name': 'gem', 'mesh': 0, 'rotation': [0.0, fmt(math.sin(math.pi / 12)), 0.0, fmt(math.cos(math.pi / 12))]},
        {'name': 'plinth', 'mesh': 1},
        {'name': 'ember', 'mesh': 2},
        {'name': 'view', 'camera': 0, 'translation': [fmt(c) for c in eye], 'rotation': quat_look(eye, target)},
        {'name': 'lamp', 'translation': [fmt(c) for c in lamp], 'rotation': quat_look(lamp, aim),
         'extensions': {'KHR_lights_punctual': {'light': 0}}},
    ]
    doc = {
        'asset': {'version': '2.0', 'generator': 'murk tools/make_gem.py'},
        'extensionsUsed': ['KHR_lights_punctual'],
        'extensions': {'KHR_lights_punctual': {'lights': [
            {'name': 'lamp', 'type': 'spot', 'color': [1.0, 0.9, 0.8], 'intensity': 3.0,
             'spot': {'innerConeAngle': 0.25, 'outerConeAngle': 0.45}}]}},
        'scene': 0,
        'scenes': [{'nodes': list(range(len(nodes)))}],
        'nodes': nodes,
        'meshes': meshes,
        'materials': materials,
        'cameras': [{'name': 'view', 'type': 'perspective',
                     'perspective': {'yfov': 0.6, 'aspectRatio': 1.3333333, 'znear': 0.01}}],
        'buffers': [{'byteLength': len(blob),
                     'uri': 'data:application/octet-stream;base64,' + base64.b64encode(blob).decode('ascii')}],
        'bufferViews': views,
        'accessors': accessors,
    }
    return json.dumps(doc, indent=1, sort_keys=True) + '\n'


def ply():
    out = ['ply', 'format ascii 1.0', 'comment murk tools/make_gem.py', 'element vertex %d' % len(GEM_V),
           'property float x', 'property float y', 'property float z', 'element face %d' % len(GEM_F),
           'property list uchar int vertex_indices', 'end_header']
    out += ['%.6f %.6f %.6f' % p for p in GEM_V]
    out += ['3 %d %d %d' % t for t in GEM_F]
    return '\n'.join(out) + '\n'


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    outdir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, '..', 'scenes', 'gem')
    os.makedirs(outdir, exist_ok=True)
    for name, text in (('gem.gltf', gltf()), ('gem.ply', ply())):
        with open(os.path.join(outdir, name), 'w', newline='\n') as f:
            f.write(text)
        print(os.path.join(outdir, name))


if __name__ == '__main__':
    main()
