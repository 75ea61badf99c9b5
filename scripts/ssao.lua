-- Screen-space ambient occlusion as seed 001 (lines 364-420, 1320-1353)
-- over the G-buffer of gbuffer.lua: the darkening factor (ssao.frag), the
-- geometry-aware blur and, at 1/2 or 1/4 size, joint bilateral upsampling
-- (filters.lua), then lit times the factor (gi_apply.frag).
local filters = require "filters"
local check = require "check"

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
for k, v in pairs(filters.defaults) do ssao.defaults[k] = v end

local function checked(o)
  local c = check.options(o, ssao.defaults, "ssao", 3)
  local L = 3
  check.need(check.whole(c.samples, 10, 300) and c.samples % 10 == 0,
             "ssao.samples must be a multiple of 10 in 10..300", c.samples, L)
  check.need(check.within(c.radius, 1e-6, 1e6), "ssao.radius must be in 1e-6..1e6 (world units)", c.radius, L)
  check.need(check.within(c.tolerance, 1e-6, 1e6), "ssao.tolerance must be in 1e-6..1e6 (world units)",
             c.tolerance, L)
  check.need(check.within(c.strength, 0, 1), "ssao.strength must be in 0..1", c.strength, L)
  check.need(check.within(c.bias, 0, 0.1), "ssao.bias must be in 0..0.1", c.bias, L)
  check.need(c.resolution == 1 or c.resolution == 2 or c.resolution == 4,
             "ssao.resolution must be 1, 2 or 4", c.resolution, L)
  check.need(c.interleave == 1 or c.interleave == 2 or c.interleave == 4,
             "ssao.interleave must be 1, 2 or 4", c.interleave, L)
  filters.check(c, "ssao", L)
  return c
end

-- Records SSAO of G applied to `lit` with options o (see ssao.defaults).
-- Returns the result, a full-size rgba16f target "ssao.lit".
function ssao.render(G, lit, o)
  o = checked(o)
  local f = o.resolution
  local ao = pass{ "ssao.ao", shader = "ssao.frag", inputs = { nrm = G.nrm, dpt = G.dpt, mat = G.mat },
                   params = { samples = o.samples, radius = o.radius, tolerance = o.tolerance,
                              strength = o.strength, bias = o.bias, interleave = o.interleave, factor = f },
                   out = target{ "ssao.ao", format = "r16f", scale = 1 / f } }
  local fo = { name = "ssao.blur", format = "r16f", factor = f, blur = o.blur, sigma_space = o.sigma_space,
               sigma_depth = o.sigma_depth, sigma_normal = o.sigma_normal }
  ao = filters.blur(ao, G, fo)
  fo.name = "ssao.upsample"
  ao = filters.upsample(ao, G, fo)
  return pass{ "ssao.apply", shader = "gi_apply.frag", inputs = { lit = lit, mat = G.mat, a = ao },
               defines = { AO = true }, out = target{ "ssao.lit", format = "rgba16f" } }
end

return ssao
