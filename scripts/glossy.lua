-- Glossy indirect light for the pbr technique's surfaces (shaders/glossy.frag):
-- screen-space reflections of the lit frame, roughness-aware, the sky where
-- the screen shows nothing (through the light propagation volumes where the
-- technique has them). Recorded only for materials = "pbr": Phong frames are
-- left as they were. docs/gi-combined.md.
-- Laid out as scripts/README.md's contract says, so modules read alike.
local gbuffer = require "gbuffer"
local lpv = require "lpv"
local options = require "options"
local sky = require "sky"

local glossy = {}

glossy.defaults = {
  enabled = false,
  samples = 4,        -- GGX directions a pixel, 1..64
  steps = 24,         -- march steps a direction, 1..256 (geometric, a pixel's footprint to the scene's diagonal)
  thickness = 0.05,   -- how far behind the depth buffer's surface a step still meets it, share of its depth, 0..1
  fallback = "volume", -- what a ray the screen cannot follow brings: "volume", the light propagation
                       -- volumes' light along it and the sky they let through, where the technique has
                       -- them (lpv+esm, isr+lpv+esm; else the sky); "sky", the sky unoccluded
}

local rules = {
  enabled = options.boolean,
  samples = options.whole(1, 64),
  steps = options.whole(1, 256),
  thickness = options.number(0, 1),
  fallback = options.one_of("volume", "sky"),
}

glossy.check = options.checker("glossy", glossy.defaults, rules)

-- Adds glossy indirect light to `lit` (full size) for frame.G with options
-- o; the sky as frame.light says. Returns a full-size rgba16f target.
function glossy.render(lit, o, frame)
  o = glossy.check(o, 2)
  local G, light = frame.G, frame.light
  local lo, hi = scene_bounds()
  local d = lo and math.sqrt((hi[1] - lo[1]) ^ 2 + (hi[2] - lo[2]) ^ 2 + (hi[3] - lo[3]) ^ 2) or 1
  if not (d > 0 and d < math.huge) then d = 1 end
  local inputs = gbuffer.inputs(G)
  inputs.lit = lit
  local defines = {}
  local params = sky.bind(light.sky, { background = light.background, samples = o.samples, steps = o.steps,
                                       thickness = o.thickness, reach = d }, defines)
  local fetches = 4 + o.samples * o.steps * 3
  local volumes = o.fallback == "volume" and frame.lpv -- lpv.render's, this frame
  if volumes then
    defines.LPV = true
    local v = volumes.o
    local occludes = lpv.bind(volumes.V, v, true, inputs, defines, params) -- the background's light too
    fetches = fetches + o.samples * (6 * (v.cascades + 1) + (occludes and v.sky_cells or 0))
  end
  return pass{ "glossy", shader = "glossy.frag", inputs = inputs, defines = defines, params = params,
               fetches = fetches, out = target{ "glossy.out", format = "rgba16f" } }
end

return glossy
