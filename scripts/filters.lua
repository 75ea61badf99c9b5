-- Geometry-aware filters any effect can use over the G-buffer of
-- gbuffer.lua (seed 001, lines 684-713, 940-1000, 1295-1307):
--   filters.blur     separable bilateral blur (bilateral.frag): spatial
--                    Gaussian, range terms on the distance off the centre's
--                    tangent plane and on the normals' angle; vertical pass
--                    then horizontal, as the seed
--   filters.upsample 3 x 3 joint bilateral upsampling (upsample.frag) from
--                    1/2 or 1/4 of the output to full size
-- Both take one target or a pair (filtered with the same weights through
-- two outputs) and return as many. filters.smooth does both for an effect.
local options = require "options"

local filters = {}

-- What an effect exposes for its blur, with defaults: an 11 x 11 kernel.
filters.defaults = {
  blur = 11,            -- kernel side in texels, odd, 1..65 (1: no blur)
  sigma_space = 2.5,    -- spatial Gaussian sigma, texels, > 0
  sigma_depth = 0.02,   -- off-plane distance of sigma, as a fraction of the depth, > 0
  sigma_normal = 0.2,   -- 1 - cos(angle) between normals of sigma, > 0
}

local rules = {
  blur = options.odd(1, 65),
  sigma_space = options.number(1e-6, 1e6),
  sigma_depth = options.number(1e-6, 1e6),
  sigma_normal = options.number(1e-6, 1e6),
}

-- Adds the filter options to an effect's defaults and their rules to its
-- rules (for options.check).
function filters.expose(defaults, effect_rules)
  for k, v in pairs(filters.defaults) do defaults[k] = v end
  for k, r in pairs(rules) do effect_rules[k] = r end
end

local function list_of(src)
  if type(src) == "table" then
    if #src < 1 or #src > 2 then error("filters: give one target or a pair", 3) end
    return src
  end
  return { src }
end

-- Blurs src (a target or {a, b}) at 1/o.factor of G's size.
-- o = { name =, format =, factor = 1, blur =, sigma_space =, sigma_depth =, sigma_normal =, age =, narrow = }
-- age (optional): temporal reuse's history state at that size, whose
-- pixels of n frames take fewer taps (bilateral.frag's AGE): n^-narrow of them.
function filters.blur(src, G, o)
  local list, f = list_of(src), o.factor or 1
  if o.blur <= 1 then return table.unpack(list) end
  for _, axis in ipairs{ { "y", { 0, 1 } }, { "x", { 1, 0 } } } do
    local name, outs = o.name .. "_" .. axis[1], {}
    for i = 1, #list do
      outs[i] = target{ name .. (i > 1 and i or ""), format = o.format, scale = 1 / f }
    end
    pass{ name, shader = "bilateral.frag",
          inputs = { src = list[1], src2 = list[2], nrm = G.nrm, dpt = G.dpt, mat = G.mat, age = o.age },
          params = { axis = axis[2], radius = (o.blur - 1) // 2, sigma_space = o.sigma_space,
                     sigma_depth = o.sigma_depth, sigma_normal = o.sigma_normal, factor = f,
                     narrow = o.age and o.narrow or nil },
          defines = { PAIR = #list == 2, AGE = o.age ~= nil }, out = outs }
    list = outs
  end
  return table.unpack(list)
end

-- Brings src (a target or {a, b}) from 1/o.factor (2 or 4) of G's size to
-- full size. o = { name =, format =, factor =, sigma_depth =, sigma_normal = }
function filters.upsample(src, G, o)
  local list, outs = list_of(src), {}
  if o.factor == 1 then return table.unpack(list) end
  for i = 1, #list do outs[i] = target{ o.name .. (i > 1 and i or ""), format = o.format } end
  pass{ o.name, shader = "upsample.frag",
        inputs = { src = list[1], src2 = list[2], nrm = G.nrm, dpt = G.dpt, mat = G.mat },
        params = { factor = o.factor, sigma_depth = o.sigma_depth, sigma_normal = o.sigma_normal },
        defines = { PAIR = #list == 2 }, out = outs }
  return table.unpack(outs)
end

-- Blurs src (a target or {a, b}) at 1/factor of G's size and brings it to
-- full size, with the filter fields of an effect's checked options o; age
-- and narrow as filters.blur's. Passes and targets are named "<prefix>.blur_x" ...
-- and "<prefix>.upsample".
function filters.smooth(src, G, o, prefix, format, factor, age, narrow)
  local fo = { name = prefix .. ".blur", format = format, factor = factor, blur = o.blur,
               sigma_space = o.sigma_space, sigma_depth = o.sigma_depth, sigma_normal = o.sigma_normal, age = age,
               narrow = narrow }
  local blurred = { filters.blur(src, G, fo) }
  fo.name = prefix .. ".upsample"
  return filters.upsample(blurred, G, fo)
end

return filters
