-- The image through rippled glass (glass.frag: procedural ripples), the seed
-- viewer's F8.
-- A one-pass post effect: they read alike (examples/tint.lua).
local options = require "options"

local glass = {}

glass.defaults = {
  enabled = false,
  strength = 5,   -- largest shift in pixels, 0..256
  scale = 24,     -- ripple wavelength in pixels, > 0
  tint = 0.97,    -- grey the glass lets through, 0..1
}

local rules = {
  enabled = options.boolean,
  strength = options.number(0, 256),
  scale = options.positive(1e5),
  tint = options.number(0, 1),
}

glass.check = options.checker("glass", glass.defaults, rules)

function glass.render(src, o)
  o = glass.check(o, 2)
  if not o.enabled then return src end
  return pass{ "glass", shader = "glass.frag", inputs = { src = src },
               params = { strength = o.strength, scale = o.scale, tint = { o.tint, o.tint, o.tint } },
               out = target{ "glass", format = "rgba16f" } }
end

return glass
