# Bakes examples/fire/mantaflow_fire.vdb: Blender's Mantaflow smoke and fire, 32^3, 30 frames, to
# OpenVDB (Debian's Blender 3.4.1; about 8 s on 2 cores). Run:
#   blender -b --factory-startup --python examples/fire/bake.py -- OUT_DIR
# The last frame is OUT_DIR/cache/data/fluid_data_0030.vdb (grids density, flame, temperature,
# velocity, shadow; half floats; voxel size 0.0625). Mantaflow writes the grid without the domain
# object's transform: it lies over [0, 2]^3 with z up, not over the domain cube at [-1, 1]^3.
import os
import sys

import bpy

out = os.path.abspath(sys.argv[sys.argv.index("--") + 1] if "--" in sys.argv else "mantaflow_bake")
cache = os.path.join(out, "cache")
os.makedirs(cache, exist_ok=True)
for ob in list(bpy.data.objects):
    bpy.data.objects.remove(ob, do_unlink=True)
scene = bpy.context.scene
scene.frame_start, scene.frame_end = 1, 30

bpy.ops.mesh.primitive_cube_add(size=2.0, location=(0, 0, 0))
domain = bpy.context.active_object
bpy.ops.object.modifier_add(type='FLUID')
ds = domain.modifiers["Fluid"]
ds.fluid_type = 'DOMAIN'
ds = ds.domain_settings
ds.domain_type = 'GAS'
ds.resolution_max = 32
ds.cache_type = 'ALL'
ds.cache_data_format = 'OPENVDB'
ds.cache_directory = cache
ds.cache_frame_start, ds.cache_frame_end = 1, 30

bpy.ops.mesh.primitive_uv_sphere_add(radius=0.3, location=(0, 0, -0.6))
flow = bpy.context.active_object
bpy.ops.object.modifier_add(type='FLUID')
fm = flow.modifiers["Fluid"]
fm.fluid_type = 'FLOW'
fm.flow_settings.flow_type = 'BOTH'  # smoke and fire: flame and temperature grids
fm.flow_settings.flow_behavior = 'INFLOW'
fm.flow_settings.flow_source = 'MESH'

# Debian's Blender 3.4.1 with a resumable cache: a flow added to a domain already set up fails on
# the next update ("'NoneType' object has no attribute 'getDataPointer'": the heat and flame
# grids were never made). Setting the cache again resets the domain with the flow's fields known.
ds.cache_type = 'ALL'
ds.cache_directory = cache
bpy.context.view_layer.update()

bpy.context.view_layer.objects.active = domain
domain.select_set(True)
with bpy.context.temp_override(object=domain, active_object=domain, selected_objects=[domain], scene=scene):
    bpy.ops.fluid.bake_all()
print("baked to", os.path.join(cache, "data"))
