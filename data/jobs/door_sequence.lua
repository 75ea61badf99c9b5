-- The door scene (data/gen_scenes.c) as a sequence against POV-Ray
-- references, one a frame: the door swings open from 0.5 to 1.5 s (frames 4
-- to 12 at 8 fps), letting the sun in. `limn report` over it prints each
-- setting's mean error over the frames, flicker, and the lag after frame 12,
-- where the door stops.
return {
  scenes = { "data/scenes/door.glb" },
  techniques = { "dl+esm" },
  sizes = { "128x96" },
  set = { ambient = 0 },
  time = { start = 0, stop = 2.5, fps = 8 },
  events = { 12 },
  output = "out/door_sequence/{camera}_{technique}_{frame}.png",
}
