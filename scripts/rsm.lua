-- Indirect light from reflective shadow maps (seed 004, lines 858-958), on
-- POV-Ray's scale (/work/shared/design/gi-scale.md). The shadow pass writes
-- the maps when this module asks (shadow.render(o, G, rsm)); the gather
-- runs at a coarse size over isr.lua's coarse view of the G-buffer
-- (isr.coarse_view: no downsampling pass; rsm.frag), then the same
-- geometry-aware blur as ISR (isr.blur); the direct pass upsamples and adds
-- it (direct.frag's INDIRECT: L = D + k_a L_a albedo + k k_d albedo E).
-- The combined technique (isr+rsm+esm) runs the same gather inside ISR's
-- first march instead (rsm.bind; docs/gi-combined.md): on ISR's grid (no
-- finer than `coarse` when isr.coarse is auto), with ISR's blur and temporal
-- reuse, so there `coarse` sets the grid's bound and the samples' density.
-- Laid out as scripts/README.md's contract says, so modules read alike.
local gbuffer = require "gbuffer"
local isr = require "isr"
local options = require "options"
local shadow = require "shadow"
local ssao = require "ssao"
local temporal = require "temporal"

local rsm = {}

-- The options a pipeline exposes (pp.lua's Options.rsm), with defaults.
rsm.defaults = {
  samples = 24,      -- RSM samples a coarse pixel and light, 1..4096 (the seed: 512 at half size);
                     -- each pixel of a 4 x 4 tile takes its own block of one pattern (rsm.frag).
                     -- 24 at coarse 3: the least error of the sweep within 2.5x dl+esm's frame
                     -- time at 256 x 192 (docs/gi-combined.md: 63.0% of its indirect error
                     -- removed, where 64 at coarse 2 removed 71.8% at about 4x)
  radius = 1.0,      -- sampling disc radius in tiles of the RSM, (0, 2]
  reach = 3,         -- a directional light's RSM tile covers the sphere around what is seen,
                     -- its radius times reach, 1..64 (senders off screen; no world unit)
  resolution = 128,  -- every RSM view's texels a side, 16..8192 (shadow.resolution halved whole times,
                     -- the least at or above; spot and point lights' views too: docs/shadows.md): the
                     -- gather's cost grows with the texels its samples scatter over, and 128 removed
                     -- as much of dl+esm's indirect error as 512 (docs/gi-combined.md)
  steps = -1,        -- screen-space visibility march a sample, 0..32 (0: none; the seed's test): a
                     -- sender is dropped where a point of the segment to it lies behind the depth
                     -- buffer, within `thickness`. -1 (auto): 1 where the camera's senders are left to
                     -- the march (isr+rsm+esm, which tests only the senders it does not see; without
                     -- it the Cornell box's boxes lit what lies behind them, and the default's Pearson
                     -- fell there against POV-Ray: docs/gi-combined.md), 0 in rsm+esm's own gather
                     -- (which would test every sender, and its temporal reuse lagged twice as far
                     -- behind its fresh frame in test_motion's uncovered band)
  thickness = 0.15,  -- how far behind the depth buffer such a point blocks, a share of the depth there,
                     -- 0..16 (0: anywhere behind, the seed's test, which also dropped senders that
                     -- lie behind a near surface but not behind anything in the scene)
  solid_steps = 0,   -- points on the segment to each sender tested against the solids the lights' views
                     -- hold, 0..64 (0: none): one inside a solid (behind a surface the light sees and
                     -- before the face where that solid ends, the pass shadow.rsm_back) drops the
                     -- sender, off screen too. 16 took the yard's first bounce from 1.12-1.59 times
                     -- Cycles' to 1.01-1.34 (senders behind its buildings), but the default's gather
                     -- pass took 1.5-2.7x as long and it lost 1.1 points against Cycles on the
                     -- reference set: off by default
                     -- (docs/gi-combined.md "Senders behind solids", issue 32)
  solid_cell = 0,    -- the same test on a grid: cells of solid_cell x solid_cell RSM texels, 0, 2, 4 or 8 (0:
                     -- none), each holding the depths between which all its texels lie inside a solid
                     -- (shadow.rsm_solid); the segment to each sender is walked over the cells it crosses,
                     -- one fetch a cell, and dropped where it passes inside one (rsm.glsl's rsm_solid_between).
                     -- Off: the default's moving frame 2.07x -> 2.15x dl+esm's, but the yard's default
                     -- 39.0% -> 39.3% and the reference set 0.2 points less against either reference
                     -- (docs/gi-combined.md "A solid grid")
  solid_senders = 0, -- with solid_steps or solid_cell: the senders a pixel and light those tests run on, 0..4096
                     -- (0: every sender), the first that pass the geometry term; the rest take the share of
                     -- the tested senders' light that no solid blocked (a visibility estimated from a few
                     -- senders, applied to all). On the yard 16 points on 2 or 4 senders blocked as much as
                     -- on every sender, and the default's moving frame took 2.70x dl+esm's where every
                     -- sender's took 3.12x (docs/gi-combined.md "The first bounce's visibility on a budget")
  ray_steps = 0,     -- the combined technique: points at which an upward ray the screen lost is tested
                     -- against the lights' RSM views on its way out of the scene's box, 0..32 (0: none,
                     -- such a ray is open unless p lies under a roof); one that crosses a surface they
                     -- hold met a surface off screen (rsm.bounces above 1 carry light over it)
  trace = 0,         -- the combined technique, rsm.bounces above 1: rays a coarse pixel traced on the CPU
                     -- (engine/trace), 0, 1/16, 1/4 or 1 (0: none). One of the rays the screen lost (not
                     -- seen, inside the scene's box, or passed behind a surface) is traced, its hit lit by
                     -- its first bounce (the RSM's gather, every sender), and the pixel's rays the screen
                     -- lost bring that light as their second bounce instead of the mean of the rays it
                     -- followed (isr_bounce.frag's TRACE); under 1, one ray for a block of 2 x 2 or 4 x 4
                     -- pixels, chosen among all the block's lost rays, whose light they all take
  trace_samples = 0, -- RSM samples at each traced hit, 0..4096 (0: rsm.samples). Its light stands for every
                     -- ray the pixel lost, so its noise weighs more than a march's ray's: 96 (against 24)
                     -- took the best setting against Cycles from 81.4% to 83.3% of dl+esm's indirect error
                     -- removed, 192 no further, for 5-10 ms more of a moving 256 x 192 frame on the room
                     -- and the Cornell box (docs/gi-combined.md "Closing in on Cycles' eight bounces")
  rotate = 10,       -- pattern turn a frame in degrees with temporal reuse, 0..180 (the seed: 10;
                     -- its radii shift too); without, the pattern stays (a still camera, a still image)
  k = 1.0,           -- indirect light factor, 0..16 (1: physical)
  bounces = 2,       -- the combined technique's bounces, 1..64: 1, ISR's screen-space bounces alone
                     -- (isr.bounces); 2, its second bounce counts the rays that met surfaces the
                     -- screen cannot show as meeting ones like those it knows (and so do ISR's
                     -- later steps, isr.bounces 3 or 4, each a bounce more); beyond isr.bounces,
                     -- the last step's newest bounce goes on as a geometric series in its senders'
                     -- k_d albedo (at most 0.9 a bounce: bounded at any count). isr_bounce.frag,
                     -- from the senders ISR's march records (isr.reuse, isr.bounces 2 or more).
                     -- On the reference set
                     -- (160 x 120) 1, 2, 3, 4 remove 72.9%, 71.9%, 67.9%, 64.2% of dl+esm's indirect
                     -- error against POV-Ray (two bounces) and 67.2%, 68.4%, 71.6%, 72.5% against
                     -- Cycles (eight): 2 removes the most on the mean of the two (docs/gi-combined.md
                     -- "Bounces the screen cannot see")
  coarse = 0,        -- coarse factor a side: 1, 2, 3 or 4 (the seed: 2, half resolution); 0 (auto): 4
                     -- from 256 pixels wide, else 3 (isr.gather_factor). At the same samples a pixel
                     -- 3 removed as much error as 2 (24: 63.0% and 62.6%) on 2.25 times fewer pixels,
                     -- and 4 as much as 3 at 256 x 192 (the reference set: 62.2% and 61.8%) on 1.78
                     -- times fewer, but less below (160 x 120: 61.3% and 61.8%; isr+rsm+esm, whose
                     -- grid it bounds, 72.5% and 73.4%, at 256 x 192 74.5% and 75.7% in 2.34x dl+esm's
                     -- frame time against 2.80x; docs/gi-combined.md)
  blur = 4,          -- Gaussian taps each side at coarse size, 0..32; with temporal reuse, a pixel
                     -- whose history holds n frames takes blur / n^(1/4) (isr.blur's age)
  sky_occlusion = 1.0, -- how much screen-space ambient occlusion (ssao.frag at the gather's grid) takes
                     -- from the ambient term and the sky, 0..1 (0: none, the seed's: the bounce then
                     -- adds to an open sky; on the held-out yard rsm+esm fell 38.6% below dl+esm against
                     -- POV-Ray, docs/techniques.md); recorded only where the frame has either
  sky_reach = 1.0,   -- its reach, as ssao.reach: a share of the pixel's view depth, 1e-3..100
  temporal = {},     -- temporal reuse (scripts/temporal.lua): enabled, frames, epsilon, bias;
                     -- its history is declared at each coarse factor (pp.lua's OnCreate)
}
for k, v in pairs(temporal.defaults) do rsm.defaults.temporal[k] = v end
-- On the door sequence (docs/motion.md) from a cold start: 0.01633 mean error, 0.002354 flicker, lag 1
-- against reuse off's 0.01674, 0.002399, 0. At the shared defaults (36 frames, moving 4, narrow 1/4)
-- 0.01729, 0.002844, lag 4 (9 warmed up): 24 samples are noisy, so a running mean over many still
-- frames changes by that noise each frame, and a history kept 4 frames while the light changes lags it.
rsm.defaults.temporal.frames, rsm.defaults.temporal.moving, rsm.defaults.temporal.narrow = 3, 2.5, 0
-- Clamping (docs/motion.md "Clamping"): a spot dimmed to a quarter left the ceiling 153% too bright 6
-- frames later unclamped (converged on part of the old light, and kept), 11.9% at 6, 7.5% at 4 (test_rsm);
-- on the door sequence 6 gives 0.01638, 0.002364, lag 1 (warmed up 0.01661, 0.002257, 0), under reuse
-- off's 0.01674, 0.002399; at 4 warmed up 0.01684, over it; 2 and 3 flicker more than off.
rsm.defaults.temporal.clamp = 6

local rules = {
  samples = options.whole(1, 4096),
  radius = options.positive(2),
  reach = options.number(1, 64),
  resolution = options.whole(16, 8192),
  steps = options.whole(-1, 32),
  thickness = options.number(0, 16),
  solid_steps = options.whole(0, 64),
  solid_cell = options.one_of(0, 2, 4, 8),
  solid_senders = options.whole(0, 4096),
  ray_steps = options.whole(0, 32),
  trace = options.one_of(0, 1 / 16, 1 / 4, 1),
  trace_samples = options.whole(0, 4096),
  rotate = options.number(0, 180),
  k = options.number(0, 16),
  bounces = options.whole(1, 64),
  coarse = options.one_of(0, 1, 2, 3, 4),
  blur = options.whole(0, 32),
  sky_occlusion = options.number(0, 1),
  sky_reach = options.number(1e-3, 100),
  temporal = function(v) if type(v) ~= "table" then return "a table of temporal reuse options" end end,
}
options.declare("rsm", rules) -- checked only when a technique runs it: declared for the viewer's panel

-- Checked options (scripts/README.md: errors name the option and point at
-- the caller `level` calls up, 1: check's), with the auto coarse factor
-- resolved for this output size; shadow.render(..., o) then writes the maps.
function rsm.check(o, level)
  o = options.check("rsm", rsm.defaults, o, rules, (level or 1) + 1)
  o.temporal = temporal.check("rsm.temporal", o.temporal)
  o.coarse = isr.gather_factor(o.coarse)
  return o
end

-- Binds the RSM's gather (rsm.glsl's rsm_gather, RSM_GATHER) to a pass
-- over a grid of coarse factor f: the RSM targets R and the atlas
-- `shadows` into inputs and defines, the checked options o into params,
-- G's light set (gbuffer.lights: each light gathered for its kind alone).
-- A pixel takes o.samples at o.coarse, and on another grid as many as keep
-- the samples per unit of screen area (at least one). temporal: the pass
-- accumulates, so the pattern turns each frame (o.rotate). exclude_seen:
-- senders the camera sees are left to the combined technique's march.
-- Returns the fetches a coarse pixel (the pass's cost estimate).
function rsm.bind(inputs, defines, params, R, shadows, o, f, temporal_on, exclude_seen, G)
  local samples = math.max(1, math.floor(o.samples * (f / o.coarse) ^ 2 + 0.5))
  shadow.bind(shadows, inputs, defines)
  gbuffer.lights(G, defines)
  inputs.rsm_flux, inputs.rsm_pos = R.flux, R.pos
  local steps = o.steps >= 0 and o.steps or exclude_seen and 1 or 0 -- auto (rsm.defaults.steps)
  defines.RSM_GATHER, defines.VISIBILITY, defines.EXCLUDE_SEEN = true, steps > 0, exclude_seen
  params.rsm_samples, params.rsm_radius, params.rsm_steps = samples, o.radius, steps
  params.rsm_thickness = o.thickness
  local solids = R.back and o.solid_steps > 0 and o.solid_steps or 0 -- shadow.render made R.back for them
  if solids > 0 then inputs.rsm_back, defines.SOLIDS, params.rsm_solid_steps = R.back, true, solids end
  local grid = R.solid and o.solid_cell > 0 -- shadow.render made it
  if grid then inputs.rsm_solid, defines.SOLID_GRID = R.solid, true end
  if solids > 0 or grid then params.rsm_solid_senders = o.solid_senders end
  defines.RAY_STEPS = exclude_seen and o.ray_steps > 0 and o.ray_steps or nil
  params.rsm_rotate = temporal_on and o.rotate / 360 or 0
  local tested = o.solid_senders > 0 and math.min(o.solid_senders, samples) or samples -- senders the solid tests see
  return samples * (2 + steps * 2 + (exclude_seen and 1 or 0)) + tested * (solids * 2 + (grid and 8 or 0))
end

-- Records the gather over the coarse view C (isr.coarse_view, factor f) of
-- G, whose depth it writes, from the RSM targets R (shadow.render's second
-- result) and the atlas `shadows`; with access (ssao.occlusion at f), E's a
-- is the share of open sky (o.sky_occlusion of it). Returns the coarse E and, with temporal
-- reuse, the history it wrote (temporal.bind).
function rsm.gather(C, f, R, shadows, o, kept, access, G)
  local inputs, defines, params = gbuffer.inputs(C), { STRIDE = C.stride, Z = true }, {}
  if access then
    inputs.access, defines.ACCESS, params.sky_occlusion = access, true, o.sky_occlusion
  end
  local turning = o.temporal.enabled and (o.temporal.turn == "always" or still_frames() == 0)
  local fetches = rsm.bind(inputs, defines, params, R, shadows, o, f, turning, false, G)
  local history = temporal.bind("rsm", inputs, defines, params, o.temporal, f)
  if history and history.fresh then defines.TEMPORAL_CLAMP = true end
  local E = kept and o.blur == 0 and kept.value or target{ "rsm.e", format = "rgba16f", scale = 1 / f }
  pass{ "rsm.gather", shader = "rsm.frag", inputs = inputs, defines = defines, params = params,
        fetches = 4 + fetches, out = { E, C.z, history and history.value, history and history.state,
                                       history and history.fresh } }
  return temporal.clamp("rsm", history, E), history
end

-- Declares the temporal reuse history at each coarse factor (one is made); from OnCreate.
function rsm.create() temporal.create("rsm", { 1, 2, 3, 4 }, { keep = true, clamp = true }) end

-- Records the RSM's indirect light over frame.G from the shadow atlas and
-- RSM targets (frame.shadows, frame.R: shadow.render(..., o)), with options
-- o: the gather over a coarse view of G (no pass averages its blocks
-- first), temporal reuse, the blur and, where the frame has a sky or an
-- ambient term, the screen-space occlusion of it. No input. Returns what the direct
-- pass adds (pp.lua's direct: INDIRECT in direct.frag): { C = the coarse
-- grid, E = the coarse result, k }. With temporal reuse the blurred E and
-- the grid's depth are kept (temporal.kept, as ISR's); a settled frame
-- (temporal.settled) returns them and records neither the gather nor the blur.
function rsm.render(_, o, frame)
  o = rsm.check(o, 2)
  local f = o.coarse
  local C = isr.coarse_view(frame.G, nil, f, "rsm")
  local kept = o.temporal.enabled and temporal.kept("rsm", f) or nil
  if kept then
    C.z = kept.z
    if temporal.settled(o.temporal) then return { C = C, E = kept.value, k = o.k } end
  end
  local light = frame.light
  local access = o.sky_occlusion > 0 and (light.sky or light.ambient[1] > 0) and
                 ssao.occlusion(frame.G, ssao.check({ reach = o.sky_reach }, 2), f, "rsm.ao") or nil
  local E, history = rsm.gather(C, f, frame.R, frame.shadows, o, kept, access, frame.G)
  return { C = C, E = isr.blur(E, C, f, o.blur, history and history.state, kept and kept.value, o.temporal.narrow),
           k = o.k }
end

-- The gather as the first march of the frame's lighting takes it (isr.render's
-- light.rsm; pp.lua's joins = "march"), with options o: { coarse = the RSM's
-- coarse factor, bind = function(inputs, defines, params, f, temporal_on) that
-- binds it (rsm.bind) and returns its fetches, bind_all = the same without temporal
-- reuse for the gather at the traced hits (rsm.trace: every sender, no visibility test, rsm.trace_samples),
-- bounces, trace }. With split, the senders the camera sees are the march's. Its
-- temporal reuse is the march's.
function rsm.march(o, frame)
  o = rsm.check(o, 2)
  local row = frame.technique
  if o.temporal.enabled then
    error(string.format("%s takes temporal reuse from %s.temporal (one pass gathers both); rsm.temporal is for "
                        .. "rsm's own gather", row[1], row.lighting), 2)
  end
  return { coarse = o.coarse, bounces = o.bounces, trace = o.trace,
           bind = function(inputs, defines, params, f, temporal_on)
             params.rsm_k = o.k
             return rsm.bind(inputs, defines, params, frame.R, frame.shadows, o, f, temporal_on, row.split == true,
                             frame.G)
           end,
           bind_all = function(inputs, defines, params, f)
             -- The traced hits lie off screen: every sender counts, and no screen-space visibility.
             local all = {}
             for k, v in pairs(o) do all[k] = v end
             all.steps = 0
             if o.trace_samples > 0 then all.samples = o.trace_samples end
             params.rsm_k = o.k
             defines.RSM_INSIDE = true -- every sample inside its view's bounds (rsm.glsl): samples are dearest here
             return rsm.bind(inputs, defines, params, frame.R, frame.shadows, all, f, false, false, frame.G)
           end }
end

return rsm
