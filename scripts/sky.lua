-- Sky light for outdoor scenes (seed 003, section 5.3): the light of a sky,
-- a gradient from the horizon to the zenith or an equirectangular HDR map,
-- as 3-band spherical harmonics (sky_sh{}, engine/scene/sky.h) evaluated at
-- each surface's normal. It joins the ambient term (k_a times the albedo),
-- which the GI techniques occlude (ISR's and SSDO's accessibility, SSAO's
-- factor); `dl` has no visibility to apply and leaves it unoccluded. Off by
-- default, and then nothing of it is in the frame. `limn export-pov --sky`
-- writes the same gradient as a sky_sphere that POV-Ray's radiosity gathers.
local options = require "options"

local sky = {}

-- Radiances are the engine's (as `ambient`): a uniform sky of radiance L
-- gives a white Lambertian plane facing it L (shared/design/gi-scale.md).
sky.defaults = {
  enabled = false,
  zenith = "0.1,0.15,0.3",  -- radiance straight up: "r,g,b" or one grey number
  horizon = "0.3,0.32,0.35", -- radiance at the horizon and below it
  intensity = 1.0,          -- multiplies the sky, 0..1e6
  map = "",                 -- an equirectangular HDR file (OpenImageIO) instead of the gradient:
                            -- top row the zenith, the middle column looking along -Z
}

local function colour(v) return options.rgb(v, 1e6) end

local rules = {
  enabled = options.boolean,
  zenith = options.colour(1e6),
  horizon = options.colour(1e6),
  intensity = options.number(0, 1e6),
  map = function(v) if type(v) ~= "string" then return "a file name (\"\": the gradient)" end end,
}
sky.check = options.checker("sky", sky.defaults, rules)

-- The sky's pass parameters (sky_r, sky_g, sky_b: shaders/sky.glsl), or nil
-- when it is off.
function sky.light(o)
  o = sky.check(o, 2)
  if not o.enabled then return nil end
  local sh = sky_sh{ zenith = colour(o.zenith), horizon = colour(o.horizon), intensity = o.intensity,
                     map = o.map ~= "" and o.map or nil }
  return { sky_r = sh[1], sky_g = sh[2], sky_b = sh[3] }
end

-- Adds the sky (from sky.light, may be nil) to a pass's params and defines;
-- with G, also the normals gi_apply.frag reads for it.
function sky.bind(light, params, defines, inputs, G)
  if light then
    for k, v in pairs(light) do params[k] = v end
    defines.SKY = true
    if inputs and G then inputs.nrm = G.nrm end
  end
  return params, defines
end

return sky
