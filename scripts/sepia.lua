-- Sepia tone (sepia.frag), the seed viewer's F11.
local options = require "options"

local sepia = {}

sepia.defaults = {
  enabled = false,
  strength = 1.0, -- 0: unchanged .. 1: full sepia
}

local rules = { enabled = options.boolean, strength = options.number(0, 1) }

sepia.check = options.checker("sepia", sepia.defaults, rules)

function sepia.render(src, o)
  o = sepia.check(o, 2)
  if not o.enabled then return src end
  return pass{ "sepia", shader = "sepia.frag", inputs = { src = src }, params = { strength = o.strength },
               out = target{ "sepia", format = "rgba16f" } }
end

return sepia
