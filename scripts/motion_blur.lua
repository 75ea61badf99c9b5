-- Camera motion blur (motion_blur.frag): each pixel reprojected with the
-- previous frame's view-projection (frame.prev_view_proj) and blurred along
-- its screen motion. A still camera leaves the image as it is.
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
  return pass{ "motion_blur", shader = "motion_blur.frag", inputs = { src = src, dpt = G.dpt },
               params = { strength = o.strength, max_length = o.max_length, samples = o.samples },
               out = target{ "motion_blur", format = "rgba16f" } }
end

return motion_blur
