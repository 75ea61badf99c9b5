-- Tutorial 3: a debug view of a target. The frame draws the G-buffer and
-- presents one of its targets (`show`) as its values are, times `scale`
-- plus `offset` (shaders/examples/show.frag): normals, -1..1, read as
-- colours with scale 0.5 and offset 0.5; depth / far as grey with scale 1.
-- Write the float image (EXR) to read the values back.
--   limn capture --script scripts/examples/debug_view.lua --set show=dpt --output depth.exr
local gbuffer = require "gbuffer"
local options = require "options"

Techniques = { "gbuffer" }
Options = { show = "nrm", scale = 0.5, offset = 0.5 }

local rules = { show = options.one_of("clr", "nrm", "dpt", "mat"), scale = options.number(-1e6, 1e6),
                offset = options.number(-1e6, 1e6) }

function OnRender(tech)
  options.fields(tech, rules, { "show", "scale", "offset" })
  local G = gbuffer.render(gbuffer.targets())
  present(pass{ "show", shader = "examples/show.frag", inputs = { src = G[tech.show] },
                params = { scale = tech.scale, offset = tech.offset }, defines = { NORMAL = tech.show == "nrm" },
                out = target{ "show", format = "rgba32f" } }, "display") -- not light: no exposure
end
