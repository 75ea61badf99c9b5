-- The image as square tiles with grout lines (tiles.frag), the seed viewer's F12.
-- A one-pass post effect: they read alike (examples/tint.lua).
local options = require "options"

local tiles = {}

tiles.defaults = {
  enabled = false,
  size = 16,     -- tile side in pixels, 1..1024
  grout = 1,     -- grout width in pixels, 0..size
  grout_grey = 0.05, -- grout colour (grey), 0..1e4
}

local rules = {
  enabled = options.boolean,
  size = options.number(1, 1024),
  grout = options.number(0, 1024),
  grout_grey = options.number(0, 1e4),
}

tiles.check = options.checker("tiles", tiles.defaults, rules)

function tiles.render(src, o)
  o = tiles.check(o, 2)
  if not o.enabled then return src end
  local g = o.grout_grey
  return pass{ "tiles", shader = "tiles.frag", inputs = { src = src },
               params = { size = o.size, grout = o.grout, grout_color = { g, g, g } },
               out = target{ "tiles", format = "rgba16f" } }
end

return tiles
