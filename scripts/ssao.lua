-- Screen-space ambient occlusion as seed 001 (lines 364-420, 1320-1353)
-- over the G-buffer of gbuffer.lua: the darkening factor (ssao.frag), the
-- geometry-aware blur and, at 1/2 or 1/4 size, joint bilateral upsampling
-- (filters.lua), then lit times the factor (gi_apply.frag).
local filters = require "filters"
local options = require "options"

local ssao = {}

ssao.defaults = {
  samples = 20,       -- a multiple of 10 in 10..300
  radius = 0.3,       -- sampling disc radius, world units (scaled by depth on screen), > 0
  tolerance = 0.3,    -- depth tolerance, world units: samples' depth reach and the occluder range, > 0
  strength = 1.0,     -- 0..1
  bias = 0.002,       -- depth bias, fraction of the depth, 0..0.1
  resolution = 1,     -- 1, 2 or 4
  interleave = 4,     -- per-pixel rotation tile side: 1, 2 or 4
}

local rules = {
  samples = options.multiple(10, 10, 300),
  radius = options.number(1e-6, 1e6),
  tolerance = options.number(1e-6, 1e6),
  strength = options.number(0, 1),
  bias = options.number(0, 0.1),
  resolution = options.one_of(1, 2, 4),
  interleave = options.one_of(1, 2, 4),
}
filters.expose(ssao.defaults, rules)

-- Records SSAO of G applied to `lit` with options o (see ssao.defaults).
-- Returns the result, a full-size rgba16f target "ssao.lit".
function ssao.render(G, lit, o)
  o = options.check("ssao", ssao.defaults, o, rules, 2)
  local f = o.resolution
  local ao = pass{ "ssao.ao", shader = "ssao.frag", inputs = { nrm = G.nrm, dpt = G.dpt, mat = G.mat },
                   params = { samples = o.samples, radius = o.radius, tolerance = o.tolerance,
                              strength = o.strength, bias = o.bias, interleave = o.interleave, factor = f },
                   out = target{ "ssao.ao", format = "r16f", scale = 1 / f } }
  ao = filters.smooth(ao, G, o, "ssao", "r16f", f)
  return pass{ "ssao.apply", shader = "gi_apply.frag", inputs = { lit = lit, mat = G.mat, a = ao },
               defines = { AO = true }, out = target{ "ssao.lit", format = "rgba16f" } }
end

return ssao
