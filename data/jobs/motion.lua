-- The scenes that move (data/gen_scenes.c), each a short sequence: from 0
-- to 1 s at 8 frames a second, 160x120. In that second the turntable's
-- camera goes a quarter round, the door starts to open (0.5 to 1.5 s), the
-- tube bends 45 degrees and the light crosses a third of the room. The views
-- are each scene's camera list; the turntable's orbiting camera is the file's
-- own camera 0 (its list holds the still front view).
return {
  scenes = { "data/scenes/turntable.glb", "data/scenes/door.glb", "data/scenes/bending_tube.glb",
             "data/scenes/moving_light.glb" },
  techniques = { "dl+esm" },
  sizes = { "160x120" },
  set = { ambient = 0.05 },
  time = { start = 0, stop = 1, fps = 8 },
  output = "out/motion/{scene}/{camera}_{technique}_{frame}.png",
}
