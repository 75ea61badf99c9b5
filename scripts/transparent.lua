-- Blended materials (glTF alphaMode BLEND: glass, foliage, decals): a forward
-- pass over the lit image, drawing them alone, back to front, lit by the
-- frame's lights, light set, shadows and ambient (and sky) light, depth tested
-- against the G-buffer's (shaders/transparent.frag). The G-buffer and its
-- lighting never see them; shadow maps draw them thinned (a lighter shadow).
-- A scene without them records nothing (scene_blended()).
local gbuffer = require "gbuffer"
local lpv = require "lpv"
local shadow = require "shadow"
local sky = require "sky"

local transparent = {}

-- Draws the blended materials over `lit` (frame F, pp.lua's: F.G, F.shadows,
-- F.light) and returns it; `tech` gives ambient and materials. Where the
-- frame has light propagation volumes (F.lpv: lpv.render), their indirect
-- light too, read at the surface (transparent.frag says why no screen-space GI).
function transparent.render(lit, tech, F)
  if not scene_blended() then return lit end
  local inputs, defines = shadow.bind(F.shadows, {}, gbuffer.lights(F.G, {}))
  defines.PBR_MATERIALS = tech.materials == "pbr" or nil
  local a = tech.ambient
  local params = sky.bind(F.light.sky, { ambient = { a, a, a } }, defines)
  if F.lpv then
    lpv.bind(F.lpv.V, F.lpv.o, false, inputs, defines, params)
    defines.LPV, params.k = true, F.lpv.o.k
  end
  scene{ "transparent", technique = "transparent", out = lit, depth = F.G.depth, clear = false, blend = true,
         inputs = inputs, defines = defines, params = params }
  return lit
end

return transparent
