-- Motion blur (motion_blur.frag): each pixel blurred along the screen motion
-- near it, from the G-buffer's velocity target (G.vel: camera, node and
-- deformation motion; pp.lua declares it when motion blur is on), else the
-- camera's alone (the previous frame's view-projection), with depth-aware
-- weights (a moving object smears over what lies behind it, not over what
-- lies in front). A still frame is left as it is.
local options = require "options"

local motion_blur = {}

motion_blur.defaults = {
  enabled = false,
  strength = 0.5,   -- shutter: fraction of the frame's motion blurred, 0..4
  max_length = 32,  -- longest streak in pixels, 0..256
  samples = 12,     -- reads along the motion, 1..64
}

local rules = {
  enabled = options.boolean,
  strength = options.number(0, 4),
  max_length = options.number(0, 256),
  samples = options.whole(1, 64),
}

-- Records motion blur of `src` (output-sized) using G.dpt. Returns src when off.
function motion_blur.render(src, o, G)
  o = options.check("motion_blur", motion_blur.defaults, o, rules, 2)
  if not o.enabled then return src end
  if not (G and G.dpt) then error("motion_blur: needs the G-buffer's depth (G.dpt)", 2) end
  local inputs, defines = { src = src, dpt = G.dpt }, {}
  if G.vel then inputs.vel, defines.VELOCITY = G.vel, true end
  return pass{ "motion_blur", shader = "motion_blur.frag", inputs = inputs, defines = defines,
               params = { strength = o.strength, max_length = o.max_length, samples = o.samples },
               out = target{ "motion_blur", format = "rgba16f" } }
end

return motion_blur
