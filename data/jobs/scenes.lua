-- Every test scene, every view, at a small size: the job test_scenes runs
-- (it writes its own copy listing whatever data/scenes holds).
return {
  scenes = { "data/scenes/cornell.glb", "data/scenes/primitives.glb", "data/scenes/office.glb",
             "data/scenes/garage.glb", "data/scenes/outdoor.glb" },
  techniques = { "dl" },
  sizes = { "96x72" },
  set = { ambient = 0.05 },
  output = "out/scenes/{scene}/{camera}_{technique}_{size}.png",
}
