-- Image-space radiosity over the G-buffer of gbuffer.lua and the frame's
-- direct light (one `direct` pass, shared by the senders and the composite).
-- Two modes:
--   physical (default; /work/shared/design/gi-scale.md) the indirect light
--            POV-Ray's radiosity computes, k_d albedo (1/pi) int L cos dw,
--            gathered along `samples` cosine-weighted rays a pixel, each
--            marched in depth (isr_march.frag) until it meets a surface of
--            the depth buffer (the sender, seen) or leaves the view; a
--            sender sends its lit radiance (its direct light, and for more
--            bounces its own indirect light of the last step)
--   seed     seed 000's ISR (Listing 3, lines 1303-1331; eq 25-29, its
--            defaults in isr.seed): albedo or lit senders in a disc of world
--            radius, no visibility, k_ISR and k_SSAO (isr.frag)
-- Steps:
--   1. seed: coarse CLR, NRM, DPT, MAT and direct light (isr_downsample.frag;
--      skipped at coarse 1); physical: none, its passes read the G-buffer at
--      each coarse texel's block centre and march through the full depth
--      buffer (isr.coarse_view)
--   2. the transport step, repeated for more bounces with the last step's
--      indirect light added to the senders' radiance (physical: the first
--      march records each ray's sender and the later bounces sum over those,
--      isr_bounce.frag, rather than march the same rays again)
--      With isr.temporal.enabled (physical), temporal reuse (temporal.lua):
--      each frame marches the next rays of the sequence, the last step
--      accumulates, and a pixel whose history has converged is not marched
--   3. a separable Gaussian blur of the coarse result that skips background
--      and does not cross depth edges (blur.frag)
--   4. bilateral upsampling and the composite (isr_light.frag)
-- Laid out as scripts/README.md's contract says, so modules read alike.
local gbuffer = require "gbuffer"
local options = require "options"
local sky = require "sky"
local temporal = require "temporal"

local isr = {}

-- The options a pipeline exposes (pp.lua's Options.isr), with their defaults.
isr.defaults = {
  mode = "physical", -- "physical" (gi-scale.md) or "seed" (seed 000's eq 25-29, options in isr.seed)
  samples = 4,       -- rays a coarse pixel, 1..256; a 4 x 4 tile of pixels takes 16 times as many
                     -- directions, which the blur averages
  steps = 10,        -- depth-march steps a ray, 1..64, spread geometrically from one coarse
                     -- pixel's footprint to where the ray leaves the view (no world unit)
  thickness = 0.02,  -- a surface hides what lies this fraction of its depth behind it, 0..1
  k = 1.0,           -- indirect light factor, 0..16 (1: physical)
  bounces = 2,       -- transport steps, 1..4 (POV-Ray's recursion_limit 2: two bounces)
  reuse = true,      -- later bounces sum over the senders the first march met (the same rays meet
                     -- the same senders every bounce); false: march again every bounce
  sky_bounce = false, -- physical, bounces above 1 with reuse: the senders send their sky light (ambient
                     -- term) too, from the second step on (isr_bounce.frag's SKY_BOUNCE)
  coarse = 0,        -- coarse factor a side: 1, 2, 3 or 4; 0 (auto): 3 below 256 pixels wide, 2,
                     -- and 4 where the coarse grid is still at least 128 texels wide (from 512
                     -- pixels wide), a grid as fine relative to the view as 256 pixels wide at 2
  blur = 6,          -- Gaussian taps each side at coarse size, 0..32 (0: no blur); 6 and not 4:
                     -- a 4 x 4 tile's interleaved rays averaged over a wider area raise Pearson
                     -- in every view of the reference set (4: 14 of 15)
  view = "lit",      -- "lit"; "indirect" (the indirect light) or "ao" (accessibility) to inspect
  temporal = {},     -- temporal reuse (scripts/temporal.lua), physical mode: enabled, frames, epsilon,
                     -- bias, confidence, refresh, moving, turn, narrow, ...; its defaults here differ
                     -- in turn, moving and narrow (below)
  seed = {           -- mode "seed": the dissertation's parameters
    samples = 48,      -- N samples a pixel, 1..256 (the seed timed 48; 80 after its fig 5.7)
    radius = 0.5,      -- sampling disc radius in world units, > 0
    k_isr = 0.5,       -- indirect light power k_ISR, 0..1
    k_ssao = 0.5,      -- ambient occlusion power k_SSAO, 0..1
    sender = "albedo", -- L_X: "albedo" (unlit, the seed) or "lit" (direct light)
    bounces = 1,       -- transport steps, 1..4 (1: the seed)
  },
}

for k, v in pairs(temporal.defaults) do isr.defaults.temporal[k] = v end
-- A still view keeps reuse off's pattern: on the door sequence (docs/motion.md) the turning pattern's
-- running mean flickered by its noise on every still frame and converged further from POV-Ray than
-- the fixed pattern (0.0491 against 0.0472 at the open door).
isr.defaults.temporal.turn = "moving"
-- isr+rsm+esm (whose RSM turns every frame, and its rays with it) on the door sequence from a cold start:
-- 0.01147 mean error, 0.002347 flicker, lag 0 against reuse off's 0.01179, 0.002365 (warmed up: 0.01117,
-- 0.002058). Reuse lowers flicker only while the world moves (a few turned patterns average out the
-- noise a fixed one drags along); on still frames a running mean changes by its noise each frame until it
-- converges, which reuse off never does: 36 frames (0.01154, 0.002601) paid that at the start and after
-- the door stopped, 4 little (still frames' error 0.0067, converged at 36 0.0067, reuse off 0.0068). At
-- moving 3 and narrow 1/4 lag 5; at moving 2 0.01123, 0.002397 (noisier while moving).
isr.defaults.temporal.frames, isr.defaults.temporal.moving, isr.defaults.temporal.narrow = 4, 2.5, 0

local views = { lit = 0, indirect = 1, ao = 2 }

local seed_rules = {
  samples = options.whole(1, 256),
  radius = options.positive(),
  k_isr = options.number(0, 1),
  k_ssao = options.number(0, 1),
  sender = options.one_of("albedo", "lit"),
  bounces = options.whole(1, 4),
}
options.declare("isr.seed", seed_rules)

local rules = {
  mode = options.one_of("physical", "seed"),
  samples = options.whole(1, 256),
  steps = options.whole(1, 64),
  thickness = options.number(0, 1),
  k = options.number(0, 16),
  bounces = options.whole(1, 4),
  reuse = options.boolean,
  sky_bounce = options.boolean,
  coarse = options.one_of(0, 1, 2, 3, 4),
  blur = options.whole(0, 32),
  view = options.one_of("lit", "indirect", "ao"),
  seed = function(v) if type(v) ~= "table" then return "a table of the seed mode's options" end end,
  temporal = function(v) if type(v) ~= "table" then return "a table of temporal reuse options" end end,
}
options.declare("isr", rules) -- checked only when a technique runs it: declared for the viewer's panel

-- The coarse G-buffer and direct light, each texel its block's average: G
-- itself at factor 1 (the seed mode's).
function isr.coarse_gbuffer(G, direct, f)
  if f == 1 then
    local C = gbuffer.inputs(G)
    C.direct = direct
    return C
  end
  local C = {
    clr = target{ "isr.clr", format = "rgba8", scale = 1 / f },
    nrm = target{ "isr.nrm", format = "rgba8", scale = 1 / f },
    dpt = target{ "isr.dpt", format = "r32f", scale = 1 / f },
    mat = target{ "isr.mat", format = "rgba8", scale = 1 / f },
    direct = target{ "isr.direct", format = "rgba16f", scale = 1 / f },
  }
  local inputs = gbuffer.inputs(G)
  inputs.direct = direct
  pass{ "isr.downsample", shader = "isr_downsample.frag", inputs = inputs,
        defines = { FACTOR = f }, out = { C.clr, C.nrm, C.dpt, C.mat, C.direct } }
  return C
end

-- A coarse grid over G without a pass of its own: the passes over it
-- (isr_march, isr_bounce, lpv_lookup, rsm and vpl with STRIDE = stride) read
-- G's texel at each coarse texel's block centre (block_centre), where a
-- coarse copy would average the block, and the march steps through G's full
-- depth. The first of them (the march, the LPV's lookup, RSM's or VPL's
-- gather) writes the grid's depth into z (0 where nothing is drawn), the
-- target "<user>.z", which the blur and the composite read (VPL: its
-- negative lights and refinement). Against the copy (isr.downsample), at
-- 160 x 120 on the room: 0.45 ms a frame less, the march 0.25 ms more (its
-- depth and senders at full size).
function isr.coarse_view(G, direct, f, user)
  return { clr = G.clr, nrm = G.nrm, dpt = G.dpt, mat = G.mat, direct = direct, stride = f, user = user,
           z = target{ user .. ".z", format = "r32f", scale = 1 / f } }
end

-- The coarse factor of an off-screen gather (rsm.coarse, vpl.coarse): c, or for
-- 0 (auto) 4 from 256 pixels wide, else 3. Its light is smooth, so at 256 x 192
-- 4 removes as much of dl+esm's indirect error on the reference set as 3 (rsm+esm
-- 62.2% and 61.8%, vpl+esm 49.9% and 49.8%) on 1.78 times fewer pixels; below,
-- 4 loses (160 x 120: rsm+esm 61.3% and 61.8%; at 64 x 48 test_gi_isr_rsm fails).
function isr.gather_factor(c)
  if c > 0 then return c end
  return output_size() >= 256 and 4 or 3
end

-- The coarse factor: o.coarse, or for 0 the auto factor at this output size.
-- Below 256 pixels wide, 3: on the reference set at 160 x 120 (tools/fidelity.sh)
-- it removes 42.1% of dl+esm's indirect error against 42.9% at 2, in 80% of the
-- frame time, where the passes' costs per frame weigh most against dl+esm's.
local function factor(o)
  if o.coarse > 0 then return o.coarse end
  local w = output_size()
  return w // 4 >= 128 and 4 or w < 256 and o.mode == "physical" and 3 or 2
end

local function coarse_target(name, f)
  return target{ name, format = "rgba16f", scale = 1 / f }
end

-- How many targets of four rays' hits the first march records for the later
-- bounces (isr_march.frag's HITS): none for one bounce, or when they would
-- not fit in the 6 colour outputs beside E and z or an index of the
-- G-buffer's texels in a float. With none, the second result says why (for
-- the options that need them).
local function hit_targets(o)
  local w, h = output_size()
  local n = (o.samples + 3) // 4
  if not o.reuse then return 0, "isr.reuse (it is false)" end
  if o.bounces < 2 then return 0, ("isr.bounces above 1 (it is %d)"):format(o.bounces) end
  if n > 6 then return 0, ("at most 24 isr.samples (it is %d)"):format(o.samples) end
  if (w + 1) * (h + 1) >= 1 << 24 then
    return 0, ("an output whose (width + 1)(height + 1) is under 2^24 (it is %dx%d)"):format(w, h)
  end
  return n
end

-- The march's params: the scene's box (scene_bounds), wider by a hundredth
-- of its diagonal a side so that a point the depth buffer places on its
-- surface lies inside; none for a scene without geometry.
local function march_params(o)
  local params = { samples = o.samples, steps = o.steps, thickness = o.thickness }
  local lo, hi = scene_bounds()
  if lo then
    local d = math.sqrt((hi[1] - lo[1]) ^ 2 + (hi[2] - lo[2]) ^ 2 + (hi[3] - lo[3]) ^ 2) * 0.01
    params.scene_lo = { lo[1] - d, lo[2] - d, lo[3] - d }
    params.scene_hi = { hi[1] + d, hi[2] + d, hi[3] + d }
  end
  return params
end

-- Checked options (scripts/README.md): errors name the option and point at
-- the caller `level` calls up (1: check's).
function isr.check(o, level)
  level = (level or 1) + 1
  o = options.check("isr", isr.defaults, o, rules, level)
  o.seed = options.check("isr.seed", isr.defaults.seed, o.seed, seed_rules, level) -- checked in either mode
  o.temporal = temporal.check("isr.temporal", o.temporal)
  return o
end

-- Declares the temporal reuse history at each coarse factor (one is made); from OnCreate.
function isr.create() temporal.create("isr", { 1, 2, 3, 4 }, { view = true, keep = true, clamp = true }) end

-- Records ISR lighting of frame.G given its direct light `direct` (lights only, no
-- ambient term: a target from direct.frag with ambient 0; isr+lpv+esm's
-- also holds the off-screen senders' light), with options o (see
-- isr.defaults) and frame.light = { ambient = {r, g, b}, background = {r, g, b},
-- sky, rsm = }. light.rsm (isr+rsm+esm): { bind = function(inputs, defines,
-- params, f, temporal) that binds the RSM's gather into the first march
-- (rsm.bind) and returns its fetches, coarse = the RSM's own coarse factor };
-- its light joins E (isr_march.frag's RSM_GATHER), and with `coarse` 0 the
-- grid is no finer than the RSM's: at 256 x 192 ISR's auto grid (2) with
-- the RSM's samples thinned to keep their density removed 65.4% of
-- dl+esm's indirect error on the reference set, the RSM's grid (3) with its
-- own samples 75.3% in less time (ISR alone: 43.2% and 43.1%).
-- Returns the lit target.
function isr.render(direct, o, frame)
  local G, light = frame.G, frame.light
  o = isr.check(o, 2)
  local seed = o.mode == "seed" and o.seed or nil
  if seed and o.temporal.enabled then error("isr.temporal is for isr.mode \"physical\"", 2) end
  if seed and light.rsm then error("isr+rsm+esm needs isr.mode \"physical\" (its march gathers the RSM)", 2) end
  local f = factor(o)
  if light.rsm and o.coarse == 0 then f = math.max(f, light.rsm.coarse) end
  local C = seed and isr.coarse_gbuffer(G, direct, f) or isr.coarse_view(G, direct, f, "isr")
  local params = { ambient = light.ambient, background = light.background, view = views[o.view] }
  if seed then
    params.k_isr, params.k_ssao = seed.k_isr, seed.k_ssao
  else
    params.k = o.k
  end
  -- With temporal reuse the final E and the grid's depth are kept (temporal.kept); once settled (a still
  -- world, every pixel converged: temporal.settled) the frame composites them without the passes.
  local kept = not seed and o.temporal.enabled and temporal.kept("isr", f) or nil
  if kept then
    C.z = kept.z
    if temporal.settled(o.temporal) then return isr.composite(G, direct, C, f, kept.value, params, false, light.sky) end
  end
  local E, E1, H, first
  local hits, no_hits = 0, "isr.mode \"physical\" (it is \"seed\")"
  if not seed then hits, no_hits = hit_targets(o) end
  if o.sky_bounce and hits == 0 then
    error("isr.sky_bounce needs the senders the first march records: " .. no_hits, 2)
  end
  -- Temporal reuse: every step reads the history (all skip the same converged pixels), the last
  -- accumulates and writes the next one after its other outputs (NEXT).
  local T, history = { inputs = {}, defines = {}, params = {} }, nil
  if not seed then history = temporal.bind("isr", T.inputs, T.defines, T.params, o.temporal, f, light.rsm ~= nil) end
  local function with_history(inputs, defines, params, out, last)
    if not history then return end
    for k, v in pairs(T.inputs) do inputs[k] = v end
    for k, v in pairs(T.defines) do defines[k] = v end
    for k, v in pairs(T.params) do params[k] = v end
    if last then
      defines.TEMPORAL_NEXT, defines.NEXT = true, #out
      out[#out + 1], out[#out + 2] = history.value, history.state
      if history.fresh then defines.TEMPORAL_CLAMP, out[#out + 1] = true, history.fresh end
    end
  end
  local steps = seed and seed.bounces or o.bounces
  -- rsm.bounces above 1: the march marks the rays that met surfaces the screen cannot show with this
  -- hit value (under 0.5: no sender), the recorded-senders bounce counts them (isr_bounce.frag's UNSEEN)
  local unseen = hits > 0 and light.rsm and light.rsm.bounces > 1 and 0.25 or nil
  -- rsm.trace: the march also writes one ray a pixel the screen lost, the CPU traces it (or one a block's), a
  -- pass lights its hit (isr.trace_light), and the recorded-senders bounce sends that light on for the lost rays
  local trace = unseen and light.rsm.trace > 0
  local rays, traced
  for b = 1, steps do
    local inputs = gbuffer.inputs(C)
    inputs.previous = E
    local name = b == 1 and "isr.transport" or "isr.transport" .. b
    if seed then
      inputs.sender = seed.sender == "lit" and C.direct or C.clr
      E = pass{ name, shader = "isr.frag", inputs = inputs, params = { samples = seed.samples, radius = seed.radius },
                fetches = 4 + seed.samples * (E and 6 or 5), -- at most: G-buffer and sender (and bounce) a sample
                defines = { BOUNCE = E ~= nil }, out = coarse_target("isr.e" .. b, f) }
    elseif H then
      local from = { clr = C.clr, mat = C.mat, first = E1, previous = E, z = history and C.z or nil }
      for k = 1, hits do from["hits" .. (k - 1)] = H[k] end
      local defines, params = { HITS = hits, STRIDE = C.stride }, { samples = o.samples }
      if unseen then
        defines.UNSEEN, defines.LAST, params.bounces, params.steps = unseen, b == steps, light.rsm.bounces, steps
      end
      if o.sky_bounce then
        from.nrm, defines.SKY_BOUNCE, params.ambient = C.nrm, true, light.ambient
        sky.bind(light.sky, params, defines)
      end
      if traced then
        from.traced, from.traced_albedo, defines.TRACE, params.step = traced[1], traced[2], true, b
        defines.TRACE_BLOCK = traced.block > 1 and traced.block or nil
      end
      E = kept and b == steps and o.blur == 0 and kept.value or coarse_target("isr.e" .. b, f)
      local out = { E }
      with_history(from, defines, params, out, b == steps)
      pass{ name, shader = "isr_bounce.frag", inputs = from, params = params, defines = defines, out = out,
            fetches = 2 + hits + (o.sky_bounce and 4 or 3) * o.samples } -- first, the hits, 3 or 4 a sending ray
    else
      inputs.sender = C.direct
      -- The later bounces add to the first E (isr_bounce.frag), or march from it: 32-bit floats in
      -- either case, so that both give the same sum.
      E = b == 1 and o.bounces > 1 and target{ "isr.e1", format = "rgba32f", scale = 1 / f }
          or kept and b == steps and o.blur == 0 and kept.value or coarse_target("isr.e" .. b, f)
      local out = { E, b == 1 and C.z or nil }
      if b == 1 and hits > 0 then
        E1, H = E, {}
        for k = 1, hits do
          H[k] = target{ "isr.hits" .. k, format = "rgba32f", scale = 1 / f }
          out[k + 2] = H[k]
        end
      end
      local defines, params = { BOUNCE = b > 1, Z = b == 1, HITS = H and hits or nil, STRIDE = C.stride }, march_params(o)
      defines.UNSEEN = H and unseen or nil
      if b == 1 and trace then
        rays = { target{ "isr.rays_o", format = "rgba32f", scale = 1 / f },
                 target{ "isr.rays_d", format = "rgba32f", scale = 1 / f } }
        defines.TRACE = #out -- the location after the hits
        out[#out + 1] = rays[1]
        out[#out + 1] = rays[2]
      end
      local fetches = 4 + o.samples * (o.steps + (b > 1 and 6 or 5)) -- the march, and the hit's G-buffer and light
      if light.rsm and b == 1 then
        fetches = fetches + light.rsm.bind(inputs, defines, params, f, o.temporal.enabled)
        first = E
      elseif light.rsm then -- its senders send only the last step's light; E adds the first step's at p
        inputs.first_step, inputs.sender, defines.FIRST = first, nil, true
      end
      with_history(inputs, defines, params, out, b == steps)
      if rays and b == 1 and #out > 8 then
        error(string.format("rsm.trace: the march would write %d targets, at most 8 (its rays take two): lower "
                            .. "isr.samples (%d)%s", #out, o.samples,
                            o.temporal.enabled and " or turn isr.temporal off" or ""), 2)
      end
      pass{ name, shader = "isr_march.frag", inputs = inputs, params = params, defines = defines, out = out,
            fetches = fetches }
      if rays then traced = isr.trace(rays, G, f, light.rsm, history ~= nil) end
    end
  end
  E = temporal.clamp("isr", history, E)
  E = isr.blur(E, C, f, o.blur, history and history.state, kept and kept.value, o.temporal.narrow)
  return isr.composite(G, direct, C, f, E, params, seed ~= nil, light.sky)
end

-- Traces the rays the first march lost (rsm.trace; rays = { origins, directions },
-- isr_march.frag's TRACE) on the CPU (the engine's "trace", engine/trace) and
-- lights each hit with its first bounce, the RSM's gather over every sender
-- (light.rsm.bind_all; isr_trace.frag). Under one ray a coarse pixel, one ray
-- a block of pixels (rsm.trace 1/4: 2 x 2, 1/16: 4 x 4), which the engine
-- chooses among the block's lost rays (turning each frame where `turn`:
-- temporal reuse averages the choices): the tracer, the write-back and the
-- light take a target that much smaller. Returns { light, albedo, block = the
-- block's side }: what each hit sends on and its k_d albedo.
function isr.trace(rays, G, f, rsm, turn)
  local block = math.floor(1 / math.sqrt(rsm.trace) + 0.5) -- rsm.trace > 0 (checked: 1, 1/4 or 1/16)
  local w, h = output_size()
  local function blocks(n) return math.ceil(math.max(math.floor(n * (1 / f)), 1) / block) end -- as the engine sizes
  local size = block > 1 and { blocks(w), blocks(h) } or nil
  local function coarse(name, format)
    return target{ name, format = format, scale = not size and 1 / f or nil, size = size }
  end
  local H = { clr = coarse("isr.hit_clr", "rgba8"), nrm = coarse("isr.hit_nrm", "rgba16f"),
              pos = coarse("isr.hit_pos", "rgba32f"), mat = coarse("isr.hit_mat", "rgba8") }
  cpu{ "isr.trace", fn = "trace", inputs = { rays_o = rays[1], rays_d = rays[2] }, out = { H.clr, H.nrm, H.pos, H.mat },
       params = block > 1 and { block = block, turn = turn and 1 or 0 } or nil }
  local inputs, defines, params = { hit_clr = H.clr, hit_nrm = H.nrm, hit_pos = H.pos, hit_mat = H.mat,
                                    rays_o = not size and rays[1] or nil, dpt = G.dpt }, { BLOCK = size ~= nil }, {}
  local fetches = rsm.bind_all(inputs, defines, params, f)
  local out = { coarse("isr.traced", "rgba16f"), coarse("isr.traced_albedo", "rgba16f") }
  pass{ "isr.trace_light", shader = "isr_trace.frag", inputs = inputs, defines = defines, params = params,
        out = out, fetches = 5 + fetches }
  out.block = block
  return out
end

-- A separable Gaussian blur of the coarse result E over the coarse
-- G-buffer C (a copy, or a view with its depth z: passes "<user>.blur_x"
-- and _y) that skips background and does not cross depth edges. age
-- (optional): temporal reuse's history state (g: the frames a pixel holds,
-- temporal.bind), whose pixels of n frames take a reach of radius / n^narrow
-- (blur.frag; temporal.narrow, 0: the full blur at any age): a new pixel is
-- blurred in full, a converged one a little.
-- out (optional): the target the last pass writes.
function isr.blur(E, C, f, radius, age, out, narrow)
  if radius == 0 then return E end
  local mask = not C.z and C.mat or nil -- a view's depth is its mask too
  for _, axis in ipairs{ { "x", { 1, 0 } }, { "y", { 0, 1 } } } do
    local name = (C.user or "isr") .. ".blur_" .. axis[1]
    E = pass{ name, shader = "blur.frag",
              inputs = { src = E, mask = mask, depth = C.z or C.dpt, age = age },
              params = { axis = axis[2], radius = radius, narrow = age and narrow or nil },
              defines = { MASK = mask ~= nil, DEPTH = true, AGE = age ~= nil },
              out = axis[1] == "y" and out or coarse_target(name, f) }
  end
  return E
end

-- Adds to a composite pass's inputs and defines the coarse result E over
-- the coarse grid C (a copy, or a view with its depth z) that coarse.glsl
-- upsamples.
function isr.bind_coarse(inputs, defines, C, E)
  inputs.coarse, inputs.coarse_dpt, inputs.coarse_mat = E, C.z or C.dpt, not C.z and C.mat or nil
  defines.Z_MASK = C.z ~= nil
end

-- Bilateral upsampling of the coarse E (rgb E, a A) at factor f and the
-- composite with the direct light (isr_light.frag), to the target "lit";
-- skylight (from sky.light, may be nil) joins the ambient term. Where f is
-- a multiple of 4 that divides the output, every 2 x 2 pixel quad lies
-- between the same four coarse texels, and its pixels share their reads
-- (coarse.glsl's QUAD_SHARED: about a sixth of isr.light's time, the same
-- images bit for bit; docs/benchmarks.md).
function isr.composite(G, direct, C, f, E, params, seed, skylight)
  local inputs, defines = { clr = G.clr, nrm = G.nrm, dpt = G.dpt, mat = G.mat, direct = direct }, { SEED = seed }
  isr.bind_coarse(inputs, defines, C, E)
  local w, h = output_size()
  defines.QUAD_SHARED = f % 4 == 0 and w % f == 0 and h % f == 0
  sky.bind(skylight, params, defines)
  return pass{ "isr.light", shader = "isr_light.frag", inputs = inputs, defines = defines, params = params,
               out = target{ "lit", format = "rgba16f" } }
end

return isr
