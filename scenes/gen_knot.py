#!/usr/bin/env python3
"""gen_knot.py: writes knot.rib, a closed mesh of 2304 shared-point quads
(PointsPolygons): a tube around a (2,3) torus knot, 192 rings of 12 points,
displaced by `dented`. Run from scenes/: python3 gen_knot.py > knot.rib
"""
import math

NU, NV, TUBE = 192, 12, 0.32


def curve(t):
    r = 2 + math.cos(3 * t)
    return (r * math.cos(2 * t), r * math.sin(2 * t), math.sin(3 * t))


def sub(a, b): return tuple(x - y for x, y in zip(a, b))
def add(a, b): return tuple(x + y for x, y in zip(a, b))
def mul(a, k): return tuple(x * k for x in a)
def dot(a, b): return sum(x * y for x, y in zip(a, b))
def cross(a, b): return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
def unit(a): return mul(a, 1 / math.sqrt(dot(a, a)))


points = []
for i in range(NU):
    t, h = 2 * math.pi * i / NU, 1e-4
    c = curve(t)
    d1 = mul(sub(curve(t + h), curve(t - h)), 1 / (2 * h))
    d2 = mul(sub(add(curve(t + h), curve(t - h)), mul(c, 2)), 1 / (h * h))
    T = unit(d1)
    N = unit(sub(d2, mul(T, dot(d2, T))))      # Frenet frame: periodic
    B = cross(T, N)
    for j in range(NV):
        a = 2 * math.pi * j / NV
        points.append(add(c, add(mul(N, TUBE * math.cos(a)), mul(B, TUBE * math.sin(a)))))

faces = []
for i in range(NU):
    for j in range(NV):
        i1, j1 = (i + 1) % NU, (j + 1) % NV
        faces.append((i * NV + j, i * NV + j1, i1 * NV + j1, i1 * NV + j))
# outward: the first face's normal points away from the tube's axis
p = [points[k] for k in faces[0]]
n = cross(sub(p[1], p[0]), sub(p[3], p[0]))
if dot(n, sub(p[0], curve(0))) < 0:
    faces = [f[::-1] for f in faces]

print("""##RenderMan RIB
# knot.rib: a closed mesh of %d shared-point quads (PointsPolygons), a
# tube around a (2,3) torus knot, dented by `dented`. Its vertex normals
# (area-weighted, docs/scenes.md "Meshes") keep the displaced faces
# together: no cracks, no pinholes. Written by gen_knot.py.
version 3.04
Option "searchpath" "shader" ["shaders:&"]
Display "knot.exr" "file" "rgba"
Format 320 240 1
PixelSamples 2 2
ShadingRate 1
Projection "perspective" "fov" [40]

Translate 0 0 9.5
Rotate -35 1 0 0

WorldBegin
  LightSource "ambientlight" 1 "intensity" [0.15]
  LightSource "distantlight" 2 "intensity" [0.9] "from" [-2 4 -3] "to" [0 0 0]
  Surface "plastic" "Ks" [0.4] "roughness" [0.1]
  AttributeBegin
    Attribute "identifier" "name" ["knot"]
    Color [0.35 0.55 0.8]
    Attribute "displacementbound" "sphere" [0.12]
    Displacement "dented" "Km" [0.1] "float frequency" [2] "float octaves" [2]""" % len(faces))
print("    PointsPolygons [%s]" % " ".join("4" for _ in faces))
for k in range(0, len(faces), 12):
    print(("      [" if k == 0 else "       ") + "  ".join(" ".join(str(x) for x in f) for f in faces[k:k + 12]) + ("]" if k + 12 >= len(faces) else ""))
print('      "P" [')
for k in range(0, len(points), 4):
    print("        " + "  ".join("%.5f %.5f %.5f" % q for q in points[k:k + 4]))
print("      ]")
print("""  AttributeEnd
WorldEnd""")
