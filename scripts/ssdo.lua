-- Screen-space directional occlusion (seed 001, lines 422-568, 864-948,
-- 1222-1318) over the G-buffer of gbuffer.lua and the frame's direct light
-- (direct.frag's with no ambient term; shadows go in there):
--   physical  the default: the direct light as it is, the ambient (sky) term
--             times the accessibility, plus the bounce from the lit senders
--             the occluded samples see, on POV-Ray's radiosity scale
--             (gi-scale.md; ssdo.frag, PHYSICAL): out = lit + A sky + B
--   merged    the author's variant: one pass (ssdo.frag, MERGED) gives the
--             modulation factor M per channel and the bounce from the lit
--             image; both blurred together, upsampled when computed at 1/2
--             or 1/4 size, applied as M (lit + bounce) (gi_apply.frag)
--   two_step  the original: L_dir with directional occlusion (DIRECT), then
--             the bounce from L_dir (BOUNCE); full size only (it computes
--             intensities, which do not survive subsampling, seed line 979);
--             applied as L_dir + L_ind
-- Shadows: the merged variant takes them from `lit` (give it a shadowed
-- direct pass: one line in the pipeline); the two-step one relights, and
-- light_visibility() in ssdo.frag is where a light's shadow factor goes.
-- Sampling: halton.glsl (bases 5, 2, 3, a per-pixel rotation). With
-- `adaptive`, a 1/16-size edge map (ssdo_edges.frag) picks 10, 20 or 30
-- samples a pixel and `samples` is not used.
-- Temporal reuse (ssdo.temporal, physical only; scripts/temporal.lua): the
-- pass turns its pattern each frame and accumulates (A, bounce), skipping
-- the pixels that have converged; the blur takes fewer taps where a pixel's
-- history holds more frames (filters.blur's age).
-- Laid out as scripts/README.md's contract says, so modules read alike.
local gbuffer = require "gbuffer"
local filters = require "filters"
local options = require "options"
local sky = require "sky"
local temporal = require "temporal"

local ssdo = {}

ssdo.defaults = {
  variant = "physical", -- "physical", "merged" (the seed's modulation factor) or "two_step" (the original)
  samples = 20,        -- K, a multiple of 10 in 10..300 (Halton period of bases 2 and 5)
  adaptive = false,    -- 10/20/30 samples from a 1/16-size edge map instead
  radius = 0.5,        -- sampling radius as a fraction of the pixel's view depth, > 0
  r_max = 0,           -- sampling radius in world units, >= 0 (0: `radius` instead)
  bounce = 1.0,        -- bounce strength, 0..100 (0: none; physical: 1 is physical; merged, two_step:
                       -- A_s in units of pi r_max^2 / K)
  lobe = 4,            -- light lobe exponent n of L_in (ssdo.frag), 1..64
  resolution = 1,      -- computed at 1/resolution a side: 1, 2 or 4 (physical and merged)
  interleave = 4,      -- per-pixel rotation tile side: 1 (none), 2 or 4
  temporal = {},       -- temporal reuse (scripts/temporal.lua), physical variant: enabled, frames,
                       -- epsilon, bias, confidence, refresh; its history is at 1/resolution
}
for k, v in pairs(temporal.defaults) do ssdo.defaults.temporal[k] = v end

local rules = {
  variant = options.one_of("physical", "merged", "two_step"),
  samples = options.multiple(10, 10, 300),
  adaptive = options.boolean,
  radius = options.number(1e-6, 100),
  r_max = options.number(0, 1e6),
  bounce = options.number(0, 100),
  lobe = options.number(1, 64),
  resolution = {
    options.one_of(1, 2, 4),
    function(v, c) -- the two-step variant computes intensities, which do not survive subsampling
      if c.variant == "two_step" and v ~= 1 then return '1 with variant "two_step" (it computes intensities)' end
    end,
  },
  interleave = options.one_of(1, 2, 4),
  temporal = function(v) if type(v) ~= "table" then return "a table of temporal reuse options" end end,
}
options.declare("ssdo", rules) -- checked only when a technique runs it: declared for the viewer's panel
filters.expose(ssdo.defaults, rules)

-- Checked options (scripts/README.md: errors name the option and point at
-- the caller `level` calls up, 1: check's).
function ssdo.check(o, level)
  o = options.check("ssdo", ssdo.defaults, o, rules, (level or 1) + 1)
  o.temporal = temporal.check("ssdo.temporal", o.temporal)
  if o.temporal.enabled and o.variant ~= "physical" then
    error('ssdo.temporal is for ssdo.variant "physical"', (level or 1) + 1)
  end
  return o
end

-- Declares the temporal reuse history at each resolution (one is made); from OnCreate.
function ssdo.create() temporal.create("ssdo", { 1, 2, 4 }, { view = true, keep = "output" }) end

-- Records SSDO for frame.G lit by `lit` (direct light, no ambient term) with
-- options o (see ssdo.defaults) and frame.light = { ambient = {r, g, b}, sky }.
-- A shadowed row (frame.technique.shadows) cannot take the two-step variant.
-- Returns the result, a full-size rgba16f target "ssdo.lit".
function ssdo.render(lit, o, frame)
  local G, light, row = frame.G, frame.light, frame.technique or {}
  o = ssdo.check(o, 2)
  if row.shadows and o.variant == "two_step" then
    error(row[1] .. ' cannot take ssdo.variant = "two_step" (it relights without shadows)', 2)
  end
  local f, merged, physical = o.resolution, o.variant == "merged", o.variant == "physical"
  local edges
  if o.adaptive then
    edges = pass{ "ssdo.edges", shader = "ssdo_edges.frag", inputs = { nrm = G.nrm, dpt = G.dpt, mat = G.mat },
                  out = target{ "ssdo.edges", format = "r16f", scale = 1 / 16 } }
  end
  local params = { samples = o.samples, r_max = o.r_max, radius = o.radius, bounce = o.bounce, lobe = o.lobe,
                   interleave = o.interleave, factor = f }
  local function inputs(sender)
    local t = gbuffer.inputs(G)
    t.sender, t.edges = sender, edges
    return t
  end
  -- With temporal reuse the composite is kept (temporal.kept); a settled frame (temporal.settled: the
  -- world and settings unchanged, every pixel converged) returns it without recording SSDO's passes.
  local kept = physical and o.temporal.enabled and temporal.kept("ssdo", f) or nil
  if kept and temporal.settled(o.temporal) then return kept.value end
  local a, b, history
  if merged or physical then
    a = target{ "ssdo.m", format = "rgba16f", scale = 1 / f }
    b = target{ "ssdo.bounce", format = "rgba16f", scale = 1 / f }
    local t, defines = inputs(lit), { MERGED = merged, PHYSICAL = physical, ADAPTIVE = o.adaptive }
    history = temporal.bind("ssdo", t, defines, params, o.temporal, f)
    pass{ physical and "ssdo.physical" or "ssdo.merged", shader = "ssdo.frag", inputs = t, params = params,
          defines = defines, out = { a, b, history and history.value, history and history.state } }
  else
    local defines = { DIRECT = true, ADAPTIVE = o.adaptive }
    local direct_params = sky.bind(light.sky, { ambient = light.ambient }, defines)
    for k, v in pairs(params) do direct_params[k] = v end
    a = pass{ "ssdo.direct", shader = "ssdo.frag", inputs = inputs(nil), params = direct_params, defines = defines,
              out = target{ "ssdo.direct", format = "rgba16f" } }
    b = pass{ "ssdo.indirect", shader = "ssdo.frag", inputs = inputs(a), params = params,
              defines = { BOUNCE = true, ADAPTIVE = o.adaptive },
              out = target{ "ssdo.indirect", format = "rgba16f" } }
  end
  a, b = filters.smooth({ a, b }, G, o, "ssdo", "rgba16f", f, history and history.state, o.temporal.narrow)
  local inputs_, params_, defines = { lit = lit, clr = G.clr, mat = G.mat, a = a, b = b }, { ambient = light.ambient },
    { PHYSICAL = physical, MERGED = merged, TWO_STEP = o.variant == "two_step" }
  sky.bind(light.sky, params_, defines, inputs_, G)
  return pass{ "ssdo.apply", shader = "gi_apply.frag", inputs = inputs_, params = params_, defines = defines,
               out = kept and kept.value or target{ "ssdo.lit", format = "rgba16f" } }
end

return ssdo
