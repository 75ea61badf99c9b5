-- The tutorial's post effect, a module as scripts/README.md says: each
-- channel of the image times its own gain (shaders/examples/tint.frag).
-- Every one-pass post effect has this shape, so they read alike (glass,
-- radial_blur, sepia, tiles).
local options = require "options"

local tint = {}

tint.defaults = {
  enabled = true,
  r = 1.0,         -- red's gain, 0..16
  g = 0.85,        -- green's
  b = 0.7,         -- blue's: a warm image by default
  strength = 1.0,  -- 0: unchanged .. 1: the gains in full
}

local rules = {
  enabled = options.boolean,
  r = options.number(0, 16),
  g = options.number(0, 16),
  b = options.number(0, 16),
  strength = options.number(0, 1),
}

tint.check = options.checker("tint", tint.defaults, rules)

-- Records the tint of `src` (output-sized); returns it, or src when off.
function tint.render(src, o)
  o = tint.check(o, 2)
  if not o.enabled then return src end
  return pass{ "tint", shader = "examples/tint.frag", inputs = { src = src },
               params = { gain = { o.r, o.g, o.b }, strength = o.strength },
               out = target{ "tint", format = "rgba16f" } }
end

return tint
