# import_check.py -- round trip (issue 17 item 5): import a sinew-play
# --out-gltf result with Blender's own glTF importer and check what came in.
#   blender -b --factory-startup --python-exit-code 1 -P tools/blender/import_check.py -- FILE.glb
# Exits non-zero (an exception) when the import fails or brings no mesh, no
# shape keys (the per-frame morph targets) or no shape-key animation.
import bpy, sys
import numpy
# Debian's Blender 3.4.1 importer still uses numpy.bool, which numpy 1.24
# removed (AttributeError in set_poly_smoothing for every mesh): restore the
# alias (it meant the builtin bool) so the importer itself runs unchanged.
import warnings
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    if getattr(numpy, "bool", None) is None:
        numpy.bool = bool
path = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
res = bpy.ops.import_scene.gltf(filepath=path)
if 'FINISHED' not in res:
    raise RuntimeError("import of %s: %s" % (path, res))
meshes = [o for o in bpy.context.scene.objects if o.type == 'MESH']
if len(meshes) != 1:
    raise RuntimeError("%s: %d mesh objects, want 1" % (path, len(meshes)))
m = meshes[0]
keys = m.data.shape_keys.key_blocks if m.data.shape_keys else []
if len(keys) < 2:
    raise RuntimeError("%s: %d shape keys, want the basis and one per frame" % (path, len(keys)))
ad = m.data.shape_keys.animation_data
if not ad or not ad.action or not ad.action.fcurves:
    raise RuntimeError("%s: no shape-key animation" % path)
print("import_check: %s: mesh '%s' %d vertices, %d faces, %d shape keys, action '%s' with %d fcurves (Blender %s)" %
      (path, m.name, len(m.data.vertices), len(m.data.polygons), len(keys) - 1, ad.action.name, len(ad.action.fcurves),
       bpy.app.version_string))
