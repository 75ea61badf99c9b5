-- Screen-space ambient occlusion as seed 001 (lines 364-420, 1320-1353)
-- over the G-buffer of gbuffer.lua: the darkening factor (ssao.frag), the
-- geometry-aware blur and, at 1/2 or 1/4 size, joint bilateral upsampling
-- (filters.lua), then the factor applied (gi_apply.frag): by default to the
-- ambient term alone (the light of the sky, which occluders hide), never to
-- direct light; `apply = "lit"` darkens everything, as seed 001 does.
local filters = require "filters"
local options = require "options"
local sky = require "sky"

local ssao = {}

ssao.defaults = {
  samples = 20,       -- a multiple of 10 in 10..300
  reach = 0.08,       -- radius and tolerance as a fraction of the pixel's view depth, > 0
  radius = 0,         -- sampling disc radius, world units (scaled by depth on screen), >= 0 (0: reach)
  tolerance = 0,      -- depth tolerance, world units: samples' depth reach and the occluder range,
                      -- >= 0 (0: reach)
  apply = "ambient",  -- what the factor darkens: "ambient" (the sky term) or "lit" (seed 001: all)
  strength = 1.0,     -- 0..1
  bias = 0.002,       -- depth bias, fraction of the depth, 0..0.1
  resolution = 1,     -- 1, 2 or 4
  interleave = 4,     -- per-pixel rotation tile side: 1, 2 or 4
}

local rules = {
  samples = options.multiple(10, 10, 300),
  reach = options.number(1e-6, 100),
  radius = options.number(0, 1e6),
  tolerance = options.number(0, 1e6),
  apply = options.one_of("ambient", "lit"),
  strength = options.number(0, 1),
  bias = options.number(0, 0.1),
  resolution = options.one_of(1, 2, 4),
  interleave = options.one_of(1, 2, 4),
}
filters.expose(ssao.defaults, rules)

ssao.check = options.checker("ssao", ssao.defaults, rules)

-- Records the accessibility of the G-buffer G (ssao.frag: r = A, 1 open)
-- at 1/f a side with checked options o, unfiltered, into the target `name`:
-- ssao.render's, and other modules' that occlude the sky by it (rsm.lua).
function ssao.occlusion(G, o, f, name)
  return pass{ name, shader = "ssao.frag", inputs = { nrm = G.nrm, dpt = G.dpt, mat = G.mat },
               params = { samples = o.samples, radius = o.radius, tolerance = o.tolerance, reach = o.reach,
                          strength = o.strength, bias = o.bias, interleave = o.interleave, factor = f },
               out = target{ name, format = "r16f", scale = 1 / f } }
end

-- Records SSAO of frame.G applied to `lit` (direct light, no ambient term)
-- with options o (see ssao.defaults) and frame.light = { ambient = {r, g, b}, sky }.
-- Returns the result, a full-size rgba16f target "ssao.lit".
function ssao.render(lit, o, frame)
  local G, light = frame.G, frame.light
  o = ssao.check(o, 2)
  local f = o.resolution
  local ao = filters.smooth(ssao.occlusion(G, o, f, "ssao.ao"), G, o, "ssao", "r16f", f)
  local inputs, params, defines = { lit = lit, clr = G.clr, mat = G.mat, a = ao }, { ambient = light.ambient },
    { AO = true, AO_LIT = o.apply == "lit" }
  sky.bind(light.sky, params, defines, inputs, G)
  return pass{ "ssao.apply", shader = "gi_apply.frag", inputs = inputs, params = params, defines = defines,
               out = target{ "ssao.lit", format = "rgba16f" } }
end

return ssao
