-- Radial (zoom) blur towards a centre (radial_blur.frag), the seed viewer's F9.
-- A one-pass post effect: they read alike (examples/tint.lua).
local options = require "options"

local radial_blur = {}

radial_blur.defaults = {
  enabled = false,
  centre_x = 0.5,  -- centre in the image, 0..1 from the left
  centre_y = 0.5,  -- 0..1 from the bottom
  strength = 0.1,  -- fraction of the way to the centre each pixel reaches, 0..1
  samples = 16,    -- reads a pixel, 1..64
}

local rules = {
  enabled = options.boolean,
  centre_x = options.number(-10, 10),
  centre_y = options.number(-10, 10),
  strength = options.number(0, 1),
  samples = options.whole(1, 64),
}

radial_blur.check = options.checker("radial_blur", radial_blur.defaults, rules)

function radial_blur.render(src, o)
  o = radial_blur.check(o, 2)
  if not o.enabled then return src end
  return pass{ "radial_blur", shader = "radial_blur.frag", inputs = { src = src },
               params = { centre = { o.centre_x, o.centre_y }, strength = o.strength, samples = o.samples },
               out = target{ "radial_blur", format = "rgba16f" } }
end

return radial_blur
