-- Indirect point lights with negative lights (seed 002), on POV-Ray's scale
-- (/work/shared/design/gi-scale.md), over the reflective shadow maps the
-- shadow pass writes (shadow.render(o, G, rsm), as rsm.lua). vpl.frag:
--   1. the indirect lights: N fixed Halton points in each light's RSM, one
--      texel each (position, normal, radiance times area), worked out once
--   2. gather at a coarse size (over isr.coarse_view: the G-buffer at each
--      coarse texel's block centre, no downsampling pass; the gather writes
--      the grid's depth): each pixel lit by all of them without
--      visibility (E+), and the light arriving from behind each pixel's
--      tangent plane (the seed's S_neg) with its mean direction
--   3. the M negative lights at Halton pixels of S_neg, one texel each
--   4. subtract them, at the coarse size
--   5. at full size, the coarse result where the coarse texels around a
--      pixel agree with it (the seed's discontinuity threshold), else all
--      lights again for that pixel: where any of them disagrees (recompute
--      "any", the seed) or only where all do ("all": elsewhere the ones
--      that agree)
--      and that pass lights the pixel too: L = D + k_a L_a albedo + k k_d albedo E
--      (direct.frag's, with INDIRECT)
-- Laid out as scripts/README.md's contract says, so modules read alike.
local gbuffer = require "gbuffer"
local isr = require "isr"
local options = require "options"
local shadow = require "shadow"
local sky = require "sky"

local vpl = {}

-- The options a pipeline exposes (pp.lua's Options.vpl), with defaults.
vpl.defaults = {
  lights = 100,      -- N indirect lights a light, 0..4096 (the seed: 100 with 50 negative)
  negative = 50,     -- M negative lights, 0..4096 (0: no occlusion)
  threshold = 0.1,   -- discontinuity threshold: relative depth and 1 - cos between normals, 0..2
  recompute = "all", -- where a full-size pixel gathers every light again: "any" of the 4 coarse texels
                     -- around it beyond threshold (the seed), or "all" of them, elsewhere the
                     -- bilinear weights of those within it renormalized: the same error on the
                     -- reference set (49.1% of dl+esm's indirect error removed, 49.0% with "any")
                     -- at 2.63x dl+esm's frame time at 256 x 192 against 3.41x (docs/gi-combined.md)
  coarse = 0,        -- coarse factor a side: 1, 2, 3 or 4 (the seed: 2); 0 (auto): 4 from 256 pixels
                     -- wide, else 3 (isr.gather_factor). The refinement redoes the discontinuities at
                     -- full size, so the error hardly depends on it (reference set at 160 x 120:
                     -- 49.1%, 49.0%, 49.1% of dl+esm's indirect error removed at 2, 3, 4; at 256 x 192
                     -- 49.8% at 3, 49.9% at 4), and 4 took 2.20-2.22x dl+esm's frame time at 256 x 192
                     -- where 3 took 2.26-2.50x in the same runs (3 about three quarters of 2's)
  reach = 3,         -- a directional light's RSM tile, as rsm.reach, 1..64
  resolution = 128,  -- its texels a side, as rsm.resolution, 16..8192
  focus = 1,         -- the indirect lights of a directional light's tile lie in its central part
                     -- of this side, times reach (1: the sphere around what is seen), 0.05..64
  k = 1.0,           -- indirect light factor, 0..16 (1: physical)
}

local rules = {
  lights = options.whole(0, 4096),
  negative = options.whole(0, 4096),
  threshold = options.number(0, 2),
  recompute = options.one_of("any", "all"),
  coarse = options.one_of(0, 1, 2, 3, 4),
  reach = options.number(1, 64),
  resolution = options.whole(16, 8192),
  focus = options.number(0.05, 64),
  k = options.number(0, 16),
}
options.declare("vpl", rules) -- checked only when a technique runs it: declared for the viewer's panel

-- Checked options (scripts/README.md: errors name the option and point at
-- the caller `level` calls up, 1: check's), with the auto coarse factor
-- resolved for this output size.
function vpl.check(o, level)
  o = options.check("vpl", vpl.defaults, o, rules, (level or 1) + 1)
  o.coarse = isr.gather_factor(o.coarse)
  return o
end

-- Records VPL lighting of frame.G from the shadow atlas and RSM targets
-- (frame.shadows, frame.R), with options o and frame.light = { ambient =
-- {r, g, b}, background = {r, g, b}, sky }: the refinement is the frame's
-- direct pass too (pp.lua's joins = "lit"); no input. Returns the lit target.
function vpl.render(_, o, frame)
  o = vpl.check(o, 2)
  local G, shadows, R, light = frame.G, frame.shadows, frame.R, frame.light
  local f = o.coarse
  local C = isr.coarse_view(G, nil, f, "vpl")
  local params = { indirect_count = o.lights, negative = o.negative, threshold = o.threshold,
                   focus = math.min(o.focus / o.reach, 1) }
  local coarse = function(name) return target{ name, format = "rgba16f", scale = 1 / f } end
  -- Lists of lights, a texel each: (N, RSM views) and (M, 1); at least one texel.
  local function list(name, w, h)
    return target{ name, format = "rgba32f", size = { math.max(w, 1), math.max(h, 1) } }
  end
  local L = { pos = list("vpl.light_pos", o.lights, R.views), flux = list("vpl.light_flux", o.lights, R.views) }
  local inputs, defines = shadow.bind(shadows, { rsm_flux = R.flux, rsm_nrm = R.nrm, rsm_pos = R.pos },
                                      { LIGHTS = true })
  pass{ "vpl.lights", shader = "vpl.frag", inputs = inputs, defines = defines, params = params, fetches = 3,
        out = { L.pos, L.flux } }
  -- Every pass reads the full G-buffer: the coarse ones at each block's centre (STRIDE), the refinement
  -- its own texel and the coarse texels' normals at their block centres.
  local function gbuffer_pass(define)
    local t, d = shadow.bind(shadows, gbuffer.inputs(G), { [define] = true, STRIDE = C.stride })
    t.vpl_pos, t.vpl_flux = L.pos, L.flux
    return t, d
  end
  local t, d = gbuffer_pass("GATHER")
  local E, N, D = coarse("vpl.e_plus"), coarse("vpl.neg"), coarse("vpl.neg_dir")
  pass{ "vpl.gather", shader = "vpl.frag", inputs = t, defines = d, params = params,
        fetches = 4 + o.lights * 2, out = { E, N, D, C.z } }
  local M = { pos = list("vpl.neg_pos", o.negative, 1), s = list("vpl.neg_s", o.negative, 1) }
  inputs, defines = shadow.bind(shadows, { neg = N, neg_dir = D, cdpt = C.z }, { NEGATIVES = true })
  pass{ "vpl.negatives", shader = "vpl.frag", inputs = inputs, defines = defines, params = params, fetches = 3,
        out = { M.pos, M.s } }
  local function negatives(t) t.neg_pos, t.neg_s = M.pos, M.s end
  t, d = gbuffer_pass("NEGATIVE")
  t.positive = E
  negatives(t)
  E = pass{ "vpl.negative", shader = "vpl.frag", inputs = t, defines = d, params = params,
            fetches = 5 + o.negative * 2, out = coarse("vpl.e") }
  t, d = gbuffer_pass("REFINE")
  d.RECOMPUTE_ANY = o.recompute == "any"
  t.coarse, t.cdpt = E, C.z
  negatives(t)
  local lit = { ambient = light.ambient, background = light.background, k = o.k }
  for key, v in pairs(params) do lit[key] = v end
  return pass{ "vpl.refine", shader = "vpl.frag", inputs = t, defines = gbuffer.defines(G, d),
               params = sky.bind(light.sky, lit, d),
               fetches = 4 + 12, -- where coarse texels agree; a discontinuity costs all lights again
               out = target{ "lit", format = "rgba16f" } }
end

return vpl
