#!/usr/bin/env python3
"""Writes the seed corpus of fuzz_gltf_loader (docs/fuzzing.md) into a folder (default:
tests/fuzz/corpus_gltf beside this script): small glTF files covering what the loader
reads, each a .gltf (buffer embedded as base64, or external after a line %%%) or a .glb."""
import base64
import json
import math
import pathlib
import struct
import sys


def f32(values):
    return struct.pack('<%df' % len(values), *values)


class Writer:
    def __init__(self):
        self.doc = {'asset': {'version': '2.0'}}
        self.bin = bytearray()

    def push(self, array, value):
        self.doc.setdefault(array, []).append(value)
        return len(self.doc[array]) - 1

    def view(self, data, stride=0):
        while len(self.bin) % 4:
            self.bin.append(0)
        v = {'buffer': 0, 'byteOffset': len(self.bin), 'byteLength': len(data)}
        if stride:
            v['byteStride'] = stride
        self.bin += data
        return self.push('bufferViews', v)

    def vec3s(self, points, stride=0):
        data = b''.join(f32(p) + b'\0' * (stride - 12 if stride else 0) for p in points)
        lo = [min(p[i] for p in points) for i in range(3)]
        hi = [max(p[i] for p in points) for i in range(3)]
        return self.push('accessors', {'bufferView': self.view(data, stride), 'componentType': 5126,
                                       'count': len(points), 'type': 'VEC3', 'min': lo, 'max': hi})

    def indices(self, idx, kind):
        fmt, ctype = {'B': ('<%dB', 5121), 'H': ('<%dH', 5123), 'I': ('<%dI', 5125)}[kind]
        return self.push('accessors', {'bufferView': self.view(struct.pack(fmt % len(idx), *idx)),
                                       'componentType': ctype, 'count': len(idx), 'type': 'SCALAR'})

    def gltf(self, external=False):
        d = dict(self.doc)
        b = {'byteLength': len(self.bin)}
        if external:
            b['uri'] = 'b.bin'
        else:
            b['uri'] = 'data:application/octet-stream;base64,' + base64.b64encode(bytes(self.bin)).decode()
        d['buffers'] = [b]
        text = json.dumps(d, indent=1).encode()
        return text + (b'\n%%%\n' + bytes(self.bin) if external else b'')

    def glb(self):
        d = dict(self.doc)
        d['buffers'] = [{'byteLength': len(self.bin)}]
        j = json.dumps(d).encode()
        j += b' ' * (-len(j) % 4)
        data = bytes(self.bin) + b'\0' * (-len(self.bin) % 4)
        out = struct.pack('<4sII', b'glTF', 2, 12 + 8 + len(j) + 8 + len(data))
        out += struct.pack('<II', len(j), 0x4E4F534A) + j + struct.pack('<II', len(data), 0x004E4942) + data
        return out


def quad(kind='H', normals=True, material=True):
    w = Writer()
    prim = {'attributes': {'POSITION': w.vec3s([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)])},
            'indices': w.indices([0, 1, 2, 0, 2, 3], kind)}
    if normals:
        prim['attributes']['NORMAL'] = w.vec3s([(0, 0, 1)] * 4, stride=16)
    if material:
        w.push('materials', {'pbrMetallicRoughness': {'baseColorFactor': [0.7, 0.6, 0.5, 1]},
                             'emissiveFactor': [1, 0.5, 0.2],
                             'extensions': {'KHR_materials_emissive_strength': {'emissiveStrength': 4}}})
        prim['material'] = 0
    w.push('meshes', {'primitives': [prim]})
    return w


def everything():
    w = quad('B')
    h = math.sqrt(0.5)
    strip = w.vec3s([(0, 0, 1), (1, 0, 1), (0, 1, 1), (1, 1, 1), (0, 2, 1)])
    w.doc['meshes'][0]['primitives'] += [{'attributes': {'POSITION': strip}, 'mode': 5},
                                         {'attributes': {'POSITION': strip}, 'mode': 6},
                                         {'attributes': {'POSITION': strip}, 'mode': 1}]
    w.doc['extensions'] = {'KHR_lights_punctual': {'lights': [
        {'type': 'point', 'color': [1, 0.5, 0.2], 'intensity': 20, 'range': 5},
        {'type': 'spot', 'intensity': 30, 'spot': {'innerConeAngle': 0.2, 'outerConeAngle': 0.7}},
        {'type': 'directional', 'intensity': 2}]}}
    w.push('cameras', {'type': 'perspective', 'perspective': {'yfov': 0.8, 'znear': 0.1, 'aspectRatio': 1.5}})
    w.push('cameras', {'type': 'orthographic', 'orthographic': {'xmag': 1, 'ymag': 1, 'znear': 0.1, 'zfar': 9}})
    nodes = [{'children': [1, 2, 3], 'translation': [1, 0, 0], 'rotation': [0, 0, h, h], 'scale': [2, 1, 1]},
             {'mesh': 0, 'matrix': [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1]},
             {'mesh': 0, 'scale': [-1, 1, 1]},
             {'camera': 1},
             {'camera': 0, 'translation': [0.5, 0.5, 6]},
             {'translation': [0, 0, 3], 'extensions': {'KHR_lights_punctual': {'light': 0}}},
             {'translation': [0, 3, 0], 'rotation': [-h, 0, 0, h], 'extensions': {'KHR_lights_punctual': {'light': 1}}},
             {'extensions': {'KHR_lights_punctual': {'light': 2}}}]
    w.doc['nodes'] = nodes
    w.doc['scenes'] = [{'nodes': [0, 4, 5, 6, 7]}]
    w.doc['scene'] = 0
    return w


def main():
    out = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else pathlib.Path(__file__).parent / 'corpus_gltf'
    out.mkdir(parents=True, exist_ok=True)
    seeds = {}
    for kind in 'BHI':
        w = quad(kind)
        w.doc['nodes'] = [{'mesh': 0}]
        seeds['quad_%s.gltf' % kind] = w.gltf()
    w = quad('I', normals=False, material=False)  # no scenes: every root node shows
    w.doc['nodes'] = [{'mesh': 0}]
    seeds['quad_flat_external.gltf'] = w.gltf(external=True)
    seeds['quad_flat.glb'] = w.glb()
    seeds['everything.gltf'] = everything().gltf()
    seeds['everything.glb'] = everything().glb()
    for name, data in seeds.items():
        (out / name).write_bytes(data)


if __name__ == '__main__':
    main()
