# make_gltf.py -- build a skinned, animated glTF of a Sinew example with
# Blender's own glTF exporter (issue 17 item 5). Run headless:
#   blender -b --factory-startup --python-exit-code 1 -P tools/blender/make_gltf.py -- \
#       --obj tools/examples/cow/cow.obj --desc tools/examples/cow/cow.sinew \
#       --walk cow --out tools/examples/cow_gltf/cow.glb --heads tools/examples/cow_gltf/cow_heads.txt
# The OBJ is imported (Y up), an armature gets one bone per 'joint' line of the
# description: bone NAME's head at the joint, parented to the bone of the
# joint's parent (not connected, so every head is exactly its joint), its tail
# towards its first child (leaf bones: along the parent bone, 30% of its
# length). The mesh is skinned with automatic weights, a walk cycle is keyed
# (--walk cow: legs swing, head nods; --walk biped: legs and arms swing, spine
# sways), and the scene exported as .glb (Y up: the glTF has the OBJ's axes).
# --heads writes every bone's head in the glTF's axes, one 'NAME X Y Z' per
# line, for the test that compares them with the joints sinew-bake reads from
# the inverse bind matrices.
import bpy, sys, math, argparse
from mathutils import Vector

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
ap = argparse.ArgumentParser()
ap.add_argument("--obj", required=True)
ap.add_argument("--desc", required=True)
ap.add_argument("--out", required=True)
ap.add_argument("--heads", required=True)
ap.add_argument("--walk", choices=["cow", "biped"], default="cow")
ap.add_argument("--normals", type=int, default=1)
ap.add_argument("--frames", type=int, default=24)
a = ap.parse_args(argv)

joints = []  # (name, parent, (x, y, z)) in OBJ axes
for line in open(a.desc):
    t = line.split("#")[0].split()
    if t and t[0] == "joint":
        joints.append((t[1], t[2], tuple(float(v) for v in t[3:6])))

def to_blender(p):   # OBJ / glTF (Y up) -> Blender (Z up)
    return Vector((p[0], -p[2], p[1]))

def to_gltf(v):      # Blender -> glTF (Y up)
    return (v.x, v.z, -v.y)

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.wm.obj_import(filepath=a.obj, forward_axis='NEGATIVE_Z', up_axis='Y')
mesh = [o for o in bpy.context.scene.objects if o.type == 'MESH'][0]
mesh.name = "body"
mesh.data.name = "body"
for poly in mesh.data.polygons:   # smooth: one normal per vertex, so the export splits few vertices
    poly.use_smooth = True

arm_data = bpy.data.armatures.new("skeleton")
arm = bpy.data.objects.new("skeleton", arm_data)
bpy.context.scene.collection.objects.link(arm)
bpy.context.view_layer.objects.active = arm
bpy.ops.object.mode_set(mode='EDIT')
pos = {n: to_blender(p) for n, _, p in joints}
eb = {}
for n, par, p in joints:
    b = arm_data.edit_bones.new(n)
    b.head = pos[n]
    kids = [c for c, cp, _ in joints if cp == n and (pos[c] - pos[n]).length > 1e-6]
    if kids:
        b.tail = pos[kids[0]]
    elif par != "-":
        d = pos[n] - pos[par]
        b.tail = pos[n] + d * 0.3 if d.length > 1e-6 else pos[n] + Vector((0, 0, 1))
    else:
        b.tail = pos[n] + Vector((0, 0, 1))
    eb[n] = b
for n, par, p in joints:
    if par != "-":
        eb[n].parent = eb[par]
        eb[n].use_connect = False
bpy.ops.object.mode_set(mode='OBJECT')

# skin: automatic weights (bone heat)
bpy.ops.object.select_all(action='DESELECT')
mesh.select_set(True)
arm.select_set(True)
bpy.context.view_layer.objects.active = arm
bpy.ops.object.parent_set(type='ARMATURE_AUTO')

# walk cycle: rotations keyed every 3 frames over one period
scene = bpy.context.scene
scene.render.fps = 24
scene.frame_start, scene.frame_end = 1, 1 + a.frames
arm.animation_data_create()
act = bpy.data.actions.new("walk")
arm.animation_data.action = act
bpy.context.view_layer.objects.active = arm
bpy.ops.object.mode_set(mode='POSE')
names = [n for n, _, _ in joints]
swing = {}
if a.walk == "cow":
    swing = {"hip_l": 20, "shoulder_r": 20, "hip_r": -20, "shoulder_l": -20}
    nod = {"neck": 8}
else:
    swing = {"hip_l": 25, "hip_r": -25, "shoulder_l": -15, "shoulder_r": 15, "knee_l": -10, "knee_r": 10}
    nod = {"spine": 4}
for f in range(0, a.frames + 1, 3):
    ph = 2 * math.pi * f / a.frames
    for n, amp in list(swing.items()) + list(nod.items()):
        if n not in names:
            continue
        pb = arm.pose.bones[n]
        pb.rotation_mode = 'XYZ'
        ang = math.radians(amp) * (math.sin(ph) if n in swing else math.sin(2 * ph))
        # swing about the bone's local x axis (a sideways axis for these bones)
        pb.rotation_euler = (ang, 0, 0)
        pb.keyframe_insert("rotation_euler", frame=1 + f)
bpy.ops.object.mode_set(mode='OBJECT')
scene.frame_set(1)

with open(a.heads, "w") as fh:
    fh.write("# bone heads (rest pose) in glTF axes, from Blender %s\n" % bpy.app.version_string)
    for b in arm_data.bones:
        h = arm.matrix_world @ b.head_local
        fh.write("%s %.9g %.9g %.9g\n" % ((b.name,) + to_gltf(h)))

bpy.ops.export_scene.gltf(filepath=a.out, export_format='GLB', export_yup=True, export_skins=True,
                          export_animations=True, export_normals=bool(a.normals), export_texcoords=False,
                          export_materials='NONE', export_colors=False, export_morph=False)
print("make_gltf: wrote %s with Blender %s" % (a.out, bpy.app.version_string))
