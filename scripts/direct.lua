-- The frame's direct light (shaders/direct.frag): the scene's lights over
-- the G-buffer, through the shadow maps where the frame has them, with an
-- ambient term and an off-screen source's coarse light added. pp.lua's
-- frames all start from it; a lighting module lights over it (ambient 0).
local gbuffer = require "gbuffer"
local isr = require "isr"
local shadow = require "shadow"
local sky = require "sky"

local direct = {}

-- Records frame F's direct light into target `name`: ambient `ambient`
-- (grey), the sky's light `skylight` (sky.light; nil: none) and `indirect`,
-- an off-screen source's coarse light ({ C, E, k }) upsampled (nil: none).
function direct.render(F, ambient, name, skylight, indirect)
  local inputs, defines = shadow.bind(F.shadows, gbuffer.inputs(F.G), gbuffer.defines(F.G, {}))
  local params = sky.bind(skylight, { ambient = { ambient, ambient, ambient }, background = F.light.background },
                          defines)
  if indirect then
    isr.bind_coarse(inputs, defines, indirect.C, indirect.E)
    defines.INDIRECT, params.k = true, indirect.k
  end
  return pass{ "direct", shader = "direct.frag", inputs = inputs, defines = defines,
               fetches = not F.shadows and 4 or nil, -- the G-buffer; shadow lookups vary with the lights
               params = params, out = target{ name, format = "rgba16f" } }
end

return direct
