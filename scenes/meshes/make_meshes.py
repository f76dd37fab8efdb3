#!/usr/bin/env python3
"""Writes the mesh files of the scene library (run from anywhere; deterministic output).

Each file exercises one format Assimp reads for sonarbench:
  pipe.stl       binary STL: a closed cylinder, radius 0.15 m, 6 m long along y
  rock.obj       Wavefront OBJ: a lumpy closed rock about 0.8 m across
  quay_wall.ply  ASCII PLY: a 20 m stretch of harbour wall, 4 m high, with a sloped rubble toe
  crate.dae      COLLADA, modelled in centimetres (<unit meter="0.01">), z up: a 60 x 40 x 40 cm crate
"""
import math
import os
import random
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def cylinder(radius, length, segments):
    verts, tris = [], []
    for end in (-0.5 * length, 0.5 * length):
        for i in range(segments):
            a = 2 * math.pi * i / segments
            verts.append((radius * math.cos(a), end, radius * math.sin(a)))
    verts += [(0, -0.5 * length, 0), (0, 0.5 * length, 0)]
    c0, c1 = 2 * segments, 2 * segments + 1
    for i in range(segments):
        j = (i + 1) % segments
        tris += [(i, segments + i, segments + j), (i, segments + j, j)]
        tris += [(c0, i, j), (c1, segments + j, segments + i)]
    return verts, tris


def normal(a, b, c):
    u = [b[k] - a[k] for k in range(3)]
    v = [c[k] - a[k] for k in range(3)]
    n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    length = math.sqrt(sum(x * x for x in n)) or 1.0
    return tuple(x / length for x in n)


def write_stl(path, verts, tris):
    with open(path, "wb") as f:
        f.write(b"sonarbench pipe".ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for t in tris:
            a, b, c = (verts[i] for i in t)
            f.write(struct.pack("<12fH", *normal(a, b, c), *a, *b, *c, 0))


def icosphere(subdivisions):
    t = (1 + math.sqrt(5)) / 2
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
             (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [tuple(x / math.sqrt(sum(y * y for y in v)) for x in v) for v in verts]
    tris = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
            (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
            (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        cache, new = {}, []

        def mid(i, j):
            key = (min(i, j), max(i, j))
            if key not in cache:
                m = [(verts[i][k] + verts[j][k]) / 2 for k in range(3)]
                length = math.sqrt(sum(x * x for x in m))
                verts.append(tuple(x / length for x in m))
                cache[key] = len(verts) - 1
            return cache[key]

        for a, b, c in tris:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        tris = new
    return verts, tris


def write_rock(path):
    rng = random.Random(11)
    verts, tris = icosphere(2)
    radii = (0.45, 0.38, 0.28)
    lumpy = []
    for v in verts:
        s = 1 + 0.12 * (rng.random() - 0.5)
        lumpy.append(tuple(radii[k] * v[k] * s for k in range(3)))
    with open(path, "w") as f:
        f.write("# sonarbench rock: a lumpy closed mesh about 0.9 x 0.76 x 0.56 m, origin at its centre\n")
        for v in lumpy:
            f.write("v %.5f %.5f %.5f\n" % v)
        for t in tris:
            f.write("f %d %d %d\n" % tuple(i + 1 for i in t))


def write_quay(path):
    # Cross-section in x-z (the wall face looks towards +x), extruded 20 m along y.
    section = [(-2.0, 0.0), (1.5, 0.0), (0.0, 1.0), (0.0, 4.0), (-2.0, 4.0)]
    n = len(section)
    verts = [(x, y, z) for y in (-10.0, 10.0) for (x, z) in section]
    tris = []
    for i in range(n):
        j = (i + 1) % n
        tris += [(i, j, n + j), (i, n + j, n + i)]
    for k in range(1, n - 1):  # the two end caps (a convex polygon, fanned)
        tris += [(0, k + 1, k), (n, n + k, n + k + 1)]
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\ncomment sonarbench quay wall, 20 m long, 4 m high, "
                "face at x = 0 looking to +x, rubble toe to x = 1.5 m\n")
        f.write("element vertex %d\nproperty float x\nproperty float y\nproperty float z\n" % len(verts))
        f.write("element face %d\nproperty list uchar int vertex_indices\nend_header\n" % len(tris))
        for v in verts:
            f.write("%.4f %.4f %.4f\n" % v)
        for t in tris:
            f.write("3 %d %d %d\n" % t)


def write_crate(path):
    hx, hy, hz = 30.0, 20.0, 20.0  # centimetres; the crate stands on z = 0
    verts = [(x, y, z) for z in (0.0, 2 * hz) for y in (-hy, hy) for x in (-hx, hx)]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    positions = " ".join("%g %g %g" % v for v in verts)
    indices = " ".join("%d %d %d %d %d %d" % (a, b, c, a, c, d) for a, b, c, d in quads)
    with open(path, "w") as f:
        f.write(f"""<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset>
    <contributor><authoring_tool>sonarbench make_meshes.py</authoring_tool></contributor>
    <unit name="centimeter" meter="0.01"/>
    <up_axis>Z_UP</up_axis>
  </asset>
  <library_geometries>
    <geometry id="crate-mesh" name="crate">
      <mesh>
        <source id="crate-positions">
          <float_array id="crate-positions-array" count="{3 * len(verts)}">{positions}</float_array>
          <technique_common>
            <accessor source="#crate-positions-array" count="{len(verts)}" stride="3">
              <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
            </accessor>
          </technique_common>
        </source>
        <vertices id="crate-vertices"><input semantic="POSITION" source="#crate-positions"/></vertices>
        <triangles count="{2 * len(quads)}">
          <input semantic="VERTEX" source="#crate-vertices" offset="0"/>
          <p>{indices}</p>
        </triangles>
      </mesh>
    </geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="Scene" name="Scene">
      <node id="crate" name="crate"><instance_geometry url="#crate-mesh"/></node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
""")


if __name__ == "__main__":
    write_stl(os.path.join(HERE, "pipe.stl"), *cylinder(0.15, 6.0, 32))
    write_rock(os.path.join(HERE, "rock.obj"))
    write_quay(os.path.join(HERE, "quay_wall.ply"))
    write_crate(os.path.join(HERE, "crate.dae"))
