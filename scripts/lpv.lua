-- Light propagation volumes (seed 003, section 5.2), on POV-Ray's scale
-- (/work/shared/design/gi-scale.md), over the reflective shadow maps the
-- shadow pass writes (shadow.render(o, G, rsm), as rsm.lua). Each frame:
--   1. injection (points passes, lpv_inject.vert): VPLs from every light's
--      RSM views, each a Lambertian lobe in 2-band spherical harmonics per
--      colour channel, and surfels of the G-buffer as the geometry volume's
--      blocking, into `cascades` grids of `cells`^3 cells
--      (unwrapped into cells^2 x cells*cascades textures, the seed's 1024 x
--      32 for one 32^3 grid) that follow the camera, snapped to whole cells
--   2. `steps` propagation steps to the six neighbours, blocked by the
--      geometry volume, with running sums (lpv_propagate.frag)
--   2b. with `bounces` > 1, each further bounce: the light the points
--      receive (lpv_bounce.frag), the points injected again with it times
--      their albedo, `steps` more steps, added to the sums (lpv_add.frag)
--   3. the lookup at each coarse pixel (lpv_lookup.frag), cascades as
--      distance bands, with the share of open sky the geometry volume leaves
--      (`sky_occlusion`), then ISR's blur (isr.blur); the direct pass
--      upsamples and adds it (direct.frag's INDIRECT:
--      L = D + k_a L_a albedo A + k k_d albedo E)
-- The combined technique (isr+lpv+esm) leaves the VPLs the camera sees to
-- ISR's screen-space march (docs/gi-combined.md).
-- Laid out as scripts/README.md's contract says, so modules read alike.
local gbuffer = require "gbuffer"
local isr = require "isr"
local options = require "options"

local lpv = {}

-- The options a pipeline exposes (pp.lua's Options.lpv), with defaults.
-- No default is a world length: cells follow from the scene's size. extent,
-- vpls, surfels and coarse lie on the error/time Pareto front of a sweep
-- over the reference set (docs/gi-combined.md): an extent of 6 fits every
-- cascade of the reference scenes to the scene (grids that stay put, in
-- volumes of 3.6 to 5.8 times fewer texels than at 3), and 24^2 VPLs, 16
-- surfels a row and the lookup at a quarter a side cost about 2 points of
-- the indirect error removed against 3, 48, 32 and a half.
lpv.defaults = {
  cells = 32,        -- cells a side of each cascade, 4..64 (the seed: 32)
  cascades = 3,      -- grids following the camera, each cell twice the last's, 1..4 (the seed: 3)
  steps = 5,         -- propagation steps, 0..256 (light moves up to a cell a step); 5 and not 8:
                     -- on the reference set 51.4% of dl+esm's indirect error removed against 55.6%,
                     -- a step about 0.3 ms at 256 x 192 (docs/gi-combined.md)
  extent = 6.0,      -- the coarsest cascade's side over the scene's bounding-box diagonal, 1e-3..64
  fit = "scene",     -- what the cascades are sized to: "scene" (extent times the scene's box) or "view"
                     -- (view_extent times the box the camera can see: its frustum, up to the scene's
                     -- farthest point ahead, clipped to the scene's box; cells then snap to powers of
                     -- two, so a moving camera changes them only an octave at a time). "scene": on the
                     -- reference set "view" removed 38.4% of dl+esm's indirect error against 50.7%, with
                     -- grids that follow the camera (20-65 times the cells) in 17 times lpv+esm's
                     -- frame time (docs/techniques.md)
  view_extent = 2.0, -- with fit "view", the coarsest cascade's side over that box's diagonal, 1e-3..64 (2:
                     -- on the held-out loft 20.3% of dl+esm's indirect error removed against 7.7% at 1)
  max_cell = 0,      -- the most cascade 0's cell may be in world units, 0..1e30 (0: no cap)
  cell = 0,          -- cascade 0's cell side in world units, 0..1e30 (0: from extent)
  shift = 1.0,       -- the cascades' centre lies this share of the seen distance ahead of the camera, 0..1
  vpls = 24,         -- VPLs a side a cascade, 1..1024: vpls^2 over all RSM views (a point light's six faces
                     -- share them), the injection's cost
  surfels = 16,      -- G-buffer surfels a row for the geometry volume, 0..1024 (0: nothing blocks)
  occlusion = 1.0,   -- how much the geometry volume blocks, 0..1 (0: light passes through walls)
  reach = 3,         -- a directional light's RSM tile, as rsm.reach, 1..64
  resolution = 128,  -- its texels a side, as rsm.resolution, 16..8192
  k = 1.0,           -- indirect light factor, 0..16 (1: physical)
  coarse = 8,        -- the lookup's coarse factor a side: 1, 2, 4 or 8; the volume's light varies
                     -- slowly, and the direct pass's upsampling keeps depth edges: 8 removed 51.0% of
                     -- dl+esm's indirect error on the reference set against 51.4% at 4, at 1.85x
                     -- dl+esm's frame time at 256 x 192 against 2.12x (one lookup texel where 4 were,
                     -- which llvmpipe ran on one thread either way)
  bounces = 1,       -- bounces of light the volumes carry, 1..8: each past the first injects the
                     -- VPLs and surfels again with the light the volumes bring them (times their
                     -- albedo) and propagates `steps` more steps (docs/gi-combined.md)
  sky_occlusion = 1.0, -- how much the geometry volume occludes the ambient term and the sky at each
                     -- pixel, 0..1 (0: not at all, as before; docs/gi-combined.md)
  sky_cells = 8,     -- cells the occlusion's directions cross, 1..64
  blur = 0,          -- Gaussian taps each side at coarse size, 0..32; the volume's light is smooth
                     -- already: 2 removed 0.4 points more of the indirect error for two passes
}

local rules = {
  cells = options.whole(4, 64),
  cascades = options.whole(1, 4),
  steps = options.whole(0, 256),
  extent = options.number(1e-3, 64),
  fit = options.one_of("scene", "view"),
  view_extent = options.number(1e-3, 64),
  max_cell = options.number(0, 1e30),
  cell = options.number(0, 1e30),
  shift = options.number(0, 1),
  vpls = options.whole(1, 1024),
  surfels = options.whole(0, 1024),
  occlusion = options.number(0, 1),
  reach = options.number(1, 64),
  resolution = options.whole(16, 8192),
  k = options.number(0, 16),
  coarse = options.one_of(1, 2, 4, 8),
  blur = options.whole(0, 32),
  bounces = options.whole(1, 8),
  sky_occlusion = options.number(0, 1),
  sky_cells = options.whole(1, 64),
}

lpv.check = options.checker("lpv", lpv.defaults, rules)

-- The box the frame can see: the camera's frustum from its near plane to the
-- farthest point of the scene's box [lo, hi] ahead of it, clipped to that
-- box; the scene's box where the camera sees none of it (or in OnCreate).
local function view_box(lo, hi)
  local cam = camera_view()
  if not cam then return lo, hi end
  local e, f, u, r = cam.eye, cam.forward, cam.up, cam.right
  local far = cam.near
  for i = 0, 7 do
    local d = 0
    for k = 1, 3 do d = d + (((i >> (k - 1)) & 1 == 1 and hi[k] or lo[k]) - e[k]) * f[k] end
    far = math.max(far, d)
  end
  far = math.min(far, cam.far)
  local blo, bhi = { math.huge, math.huge, math.huge }, { -math.huge, -math.huge, -math.huge }
  for _, d in ipairs{ cam.near, far } do
    local y, x = d * cam.tan_y, d * cam.tan_y * cam.aspect
    for _, sy in ipairs{ -1, 1 } do
      for _, sx in ipairs{ -1, 1 } do
        for k = 1, 3 do
          local p = e[k] + d * f[k] + sy * y * u[k] + sx * x * r[k]
          blo[k], bhi[k] = math.min(blo[k], p), math.max(bhi[k], p)
        end
      end
    end
  end
  for k = 1, 3 do
    blo[k], bhi[k] = math.max(blo[k], lo[k]), math.min(bhi[k], hi[k])
    if not (blo[k] <= bhi[k]) then return lo, hi end
  end
  return blo, bhi
end

-- Cascade 0's cell side: o.cell, or the coarsest cascade spanning o.extent
-- times the scene box's diagonal (a scene without extent: a unit, as the
-- engine's bounds of an empty scene) or, fitted to the view, o.view_extent
-- times view_box's; at most o.max_cell. Fitted to the view, the side is the
-- nearest power of two: cells of every cascade then lie on one world grid,
-- and a camera that moves changes them only when the box it sees doubles or
-- halves.
local function cell_size(o)
  if o.cell > 0 then return o.cell end
  local lo, hi = scene_bounds()
  local view = o.fit == "view"
  if lo and view then lo, hi = view_box(lo, hi) end
  local d = lo and math.sqrt((hi[1] - lo[1]) ^ 2 + (hi[2] - lo[2]) ^ 2 + (hi[3] - lo[3]) ^ 2) or 1
  if not (d > 0 and d < math.huge) then d = 1 end
  local h = (view and o.view_extent or o.extent) * d / (o.cells * 2 ^ (o.cascades - 1))
  if view then h = 2 ^ math.floor(math.log(h, 2) + 0.5) end
  if o.max_cell > 0 then h = math.min(h, o.max_cell) end
  return h
end

-- The cascades' grids (lpv.glsl) for cascade 0's cell side h: per cascade
-- and axis, where the scene's box and a cell either side fit in o.cells
-- cells, just those cells and their least corner (the grid stays put), else
-- o.cells cells that follow the camera; the blocks' first columns and the
-- volumes' size. Cascades past o.cascades (up to the uniforms' 4) are empty.
local function layout(o, h)
  local lo, hi = scene_bounds()
  local G = { h = h, n = { {}, {}, {} }, corner = { {}, {}, {} }, follow = {}, col = {} }
  local width, rows = 0, 1
  for c = 1, 4 do
    local hc, follow = h * 2 ^ (c - 1), 0
    for k = 1, 3 do
      local n, corner = o.cells, 0
      local first = lo and math.floor(lo[k] / hc) - 1
      local cells = lo and math.ceil(hi[k] / hc) + 1 - first
      if cells and cells <= o.cells then
        n, corner = cells, first * hc
      else
        follow = follow | 1 << (k - 1)
      end
      G.n[k][c], G.corner[k][c] = c <= o.cascades and n or 1, corner
    end
    G.follow[c], G.col[c] = follow, width
    if c <= o.cascades then
      width = width + G.n[1][c] * G.n[3][c]
      rows = math.max(rows, G.n[2][c])
    end
  end
  G.size = { width, rows }
  return G
end

-- The uniforms of lpv.glsl for the grids G (layout).
local function grid(o, G, params)
  params.lpv_cascades, params.lpv_cell, params.lpv_shift = o.cascades, G.h, o.shift
  params.lpv_nx, params.lpv_ny, params.lpv_nz = G.n[1], G.n[2], G.n[3]
  params.lpv_ax, params.lpv_ay, params.lpv_az = G.corner[1], G.corner[2], G.corner[3]
  params.lpv_follow, params.lpv_col, params.lpv_size = G.follow, G.col, G.size
  return params
end

-- The width of a bounce's target of the light its points receive (lpv_bounce.frag).
local BOUNCE_WIDTH = 64

-- A volume target (one colour channel, or the geometry) over the grids.
local function volume_target(grids, name) return target{ name, format = "rgba32f", size = grids.size } end

-- Records o.steps propagation steps of the wave inj (three volumes), target
-- names after "lpv." .. tag. The injected light itself (step
-- 0) is in no sum: it sits in its VPL's own cell, which a thin wall shares
-- with the other side, and would light that side too. The last step (past
-- the first) writes the sum of all steps in place of its wave (ALL).
-- Returns { all, late } (sums of steps 1 .. steps and of steps
-- steps // 2 + 1 .. steps).
local function propagate(o, grids, geometry, inj, tag)
  local wave, early, late, all = { inj[1], inj[2], inj[3] }, nil, nil, nil
  local half = o.steps // 2
  for k = 1, o.steps do
    local sum = k <= half and early or k > half and late or nil
    local last = k == o.steps and early ~= nil
    local out = {}
    for i, ch in ipairs{ "r", "g", "b" } do
      out[i] = volume_target(grids, "lpv." .. tag .. (last and "all_" or "wave_") .. ch .. k)
      out[i + 3] = volume_target(grids, "lpv." .. tag .. "sum_" .. ch .. k)
    end
    local inputs = { wave_r = wave[1], wave_g = wave[2], wave_b = wave[3], geometry = geometry }
    if sum then inputs.sum_r, inputs.sum_g, inputs.sum_b = sum[1], sum[2], sum[3] end
    if last then inputs.early_r, inputs.early_g, inputs.early_b = early[1], early[2], early[3] end
    pass{ "lpv." .. tag .. "propagate" .. k, shader = "lpv_propagate.frag", inputs = inputs,
          defines = { SUM = sum ~= nil, FIRST = k == 1, ALL = last }, params = grid(o, grids, { occlusion = o.occlusion }),
          fetches = 19 + (sum and 3 or 0) + (last and 3 or 0), out = out }
    wave = { out[1], out[2], out[3] }
    if k <= half then early = { out[4], out[5], out[6] } else late = { out[4], out[5], out[6] } end
    if last then all = wave end
  end
  return { all = all or late, late = late }
end

-- Records injection and propagation from the RSM targets R (shadow.render's
-- second result) and the G-buffer G, o.bounces times. exclude_seen: VPLs the
-- camera sees are left out (the combined technique). Returns the volumes:
-- { all = {r, g, b}, late = {r, g, b} (sums of steps 1 .. steps and of steps
-- steps // 2 + 1 .. steps over every bounce, the same targets for one step,
-- nil for none), grids = their layout, seen = R.seen, geometry = the
-- geometry volume }.
function lpv.volume(G, R, o, exclude_seen)
  local grids = layout(o, cell_size(o))
  -- Points a cascade: vpls^2 VPLs shared among the RSM views and a grid of surfels `surfels` a row. The
  -- cascades that hold the whole scene (the coarser ones from the first that does) take the same part of
  -- each RSM view and of the screen: each then takes half as many a side as the last, as many for each of
  -- its cells (the points cost about a microsecond each, and three cascades drew three times as many).
  local w, ht = output_size()
  local side = math.max(1, math.floor(o.vpls / math.sqrt(math.max(R.views, 1)) + 0.5))
  local sides, cols, rows, vpls, surfels, whole = {}, {}, {}, 0, 0, nil
  for c = 1, 4 do
    whole = whole or grids.follow[c] == 0 and c
    local thin = whole and 2 ^ (c - whole) or 1
    sides[c] = math.max(1, math.floor(side / thin + 0.5))
    cols[c] = o.surfels > 0 and math.max(1, math.floor(o.surfels / thin + 0.5)) or 0
    rows[c] = o.surfels > 0 and math.max(1, (cols[c] * ht + w // 2) // w) or 0
    if c <= o.cascades then vpls, surfels = vpls + R.views * sides[c] ^ 2, surfels + cols[c] * rows[c] end
  end
  local params = grid(o, grids, { vpl_sides = sides, rsm_views = R.views, surfel_cols = cols, surfel_rows = rows })
  local inputs = { rsm_flux = R.flux, rsm_nrm = R.nrm, rsm_pos = R.pos, nrm = G.nrm, dpt = G.dpt, mat = G.mat,
                   lpv_seen = R.seen }
  local inj = { volume_target(grids, "lpv.inject_r"), volume_target(grids, "lpv.inject_g"),
                volume_target(grids, "lpv.inject_b") }
  points{ "lpv.inject", vertex = "lpv_inject.vert", shader = "lpv_inject.frag",
          count = vpls, inputs = inputs, params = params,
          defines = { SHADOWS = true, EXCLUDE_SEEN = exclude_seen == true }, fetches = 4, out = inj }
  local geometry = points{ "lpv.geometry", vertex = "lpv_inject.vert", shader = "lpv_inject.frag",
                           count = surfels, inputs = inputs, params = params,
                           defines = { SHADOWS = true, GEOMETRY = true }, fetches = 3,
                           out = volume_target(grids, "lpv.geometry") }
  local V = propagate(o, grids, geometry, inj, "")
  -- Each bounce past the first injects the same points again, sending on the light the last bounce's
  -- volumes bring them (its own sums: the bounces before it were sent on already), propagates it
  -- into sums of its own and adds them to the total (lpv_add.frag). With surfels, they send for what
  -- the camera sees and the VPLs for the rest; the combined technique leaves what the camera sees to
  -- ISR, which sends it on through the screen.
  local bounce_cols = exclude_seen and { 0, 0, 0, 0 } or cols
  local bounce_surfels = 0
  for c = 1, o.cascades do bounce_surfels = bounce_surfels + bounce_cols[c] * rows[c] end
  local total, last = V, V
  for b = 2, o.steps > 0 and o.bounces or 1 do
    local tag = "bounce" .. b .. "."
    local count = vpls + bounce_surfels
    local function bounce_params(more)
      local params = grid(o, grids, { vpl_sides = sides, rsm_views = R.views, surfel_cols = bounce_cols,
                                      surfel_rows = rows, bounce_width = BOUNCE_WIDTH })
      for k, v in pairs(more) do params[k] = v end
      return params
    end
    local seen = exclude_seen == true or bounce_surfels > 0
    local binputs = { rsm_flux = R.flux, rsm_nrm = R.nrm, rsm_pos = R.pos, clr = G.clr, nrm = G.nrm, dpt = G.dpt,
                      mat = G.mat, lpv_seen = R.seen }
    local linputs = { all_r = last.all[1], all_g = last.all[2], all_b = last.all[3], late_r = last.late[1],
                      late_g = last.late[2], late_b = last.late[3] }
    for k, v in pairs(binputs) do linputs[k] = v end
    binputs.bounce_light = pass{ "lpv." .. tag .. "light", shader = "lpv_bounce.frag", inputs = linputs,
                                 params = bounce_params{ lpv_steps = o.steps, bounce_points = count },
                                 defines = { SHADOWS = true, BOUNCE = true, VOLUMES = true, EXCLUDE_SEEN = seen },
                                 fetches = 5 + 6 * (o.cascades + 1),
                                 out = target{ "lpv." .. tag .. "light", format = "rgba32f",
                                               size = { BOUNCE_WIDTH, math.max(1, -(-count // BOUNCE_WIDTH)) } } }
    local again = {}
    for i, ch in ipairs{ "r", "g", "b" } do again[i] = volume_target(grids, "lpv." .. tag .. "inject_" .. ch) end
    points{ "lpv." .. tag .. "inject", vertex = "lpv_inject.vert", shader = "lpv_inject.frag", count = count,
            inputs = binputs, params = bounce_params{}, fetches = 5, out = again,
            defines = { SHADOWS = true, BOUNCE = true, EXCLUDE_SEEN = seen } }
    last = propagate(o, grids, geometry, again, tag)
    local out = {}
    for i, name in ipairs{ "all_r", "all_g", "all_b", "late_r", "late_g", "late_b" } do
      out[i] = volume_target(grids, "lpv." .. tag .. "total_" .. name)
    end
    pass{ "lpv." .. tag .. "add", shader = "lpv_add.frag", params = grid(o, grids, {}), fetches = 12, out = out,
          inputs = { all_r = total.all[1], all_g = total.all[2], all_b = total.all[3], late_r = total.late[1],
                     late_g = total.late[2], late_b = total.late[3], more_r = last.all[1], more_g = last.all[2],
                     more_b = last.all[3], more_late_r = last.late[1], more_late_g = last.late[2],
                     more_late_b = last.late[3] } }
    total = { all = { out[1], out[2], out[3] }, late = { out[4], out[5], out[6] } }
  end
  return { all = total.all, late = total.late, grids = grids, seen = R.seen, geometry = geometry }
end

-- Adds what a pass needs to read the volumes V (lpv.volume) with options o
-- (lpv_light.glsl's lpv_light_from; with sky, lpv_sky_through) to its
-- inputs, defines and params. Returns whether the sky is occluded.
function lpv.bind(V, o, sky, inputs, defines, params)
  if V.late then
    inputs.all_r, inputs.all_g, inputs.all_b = V.all[1], V.all[2], V.all[3]
    inputs.late_r, inputs.late_g, inputs.late_b = V.late[1], V.late[2], V.late[3]
  end
  inputs.lpv_seen = V.seen
  local occludes = sky and o.sky_occlusion > 0 and o.surfels > 0
  if occludes then inputs.geometry = V.geometry end
  defines.VOLUMES, defines.SKY_OCCLUSION = V.late ~= nil, occludes
  params.lpv_steps, params.sky_cells, params.sky_occlusion = o.steps, o.sky_cells, o.sky_occlusion
  grid(o, V.grids, params)
  return occludes
end

-- Records the lookup over the coarse view C (isr.coarse_view, factor f),
-- whose depth it writes, in the volumes V (lpv.volume); with sky, the share
-- of open sky in its a (o.sky_occlusion). Returns the coarse E.
function lpv.gather(C, f, V, o, sky)
  local inputs, defines, params = gbuffer.inputs(C), { STRIDE = C.stride, Z = true }, {}
  local occludes = lpv.bind(V, o, sky, inputs, defines, params)
  local E = target{ "lpv.e", format = "rgba16f", scale = 1 / f }
  pass{ "lpv.lookup", shader = "lpv_lookup.frag", inputs = inputs, defines = defines, params = params,
        fetches = 4 + 6 * (o.cascades + 1) + (occludes and 8 * o.sky_cells or 0), out = { E, C.z } }
  return E
end

-- Records the LPV's indirect light over frame.G from the RSM targets
-- frame.R, with options o; no input. frame.lpv keeps the volumes and options
-- for other passes that read them (lpv.bind: glossy.lua, transparent.lua). With the row's split, VPLs the camera
-- sees are left to the frame's lighting (lpv.volume's exclude_seen).
-- Returns what the direct pass adds (pp.lua's direct: INDIRECT in
-- direct.frag): { C = the coarse grid, E = the coarse result, k }; E's a,
-- the share of open sky, occludes the direct pass's ambient term (without
-- the split: there ISR's composite occludes it). Leaves the volumes and
-- options in frame.lpv ({ V, o }) for later passes (glossy.lua's fallback).
function lpv.render(_, o, frame)
  o = lpv.check(o, 2)
  local G, f, split = frame.G, o.coarse, frame.technique and frame.technique.split
  local C = isr.coarse_view(G, nil, f, "lpv")
  local V = lpv.volume(G, frame.R, o, split)
  local E = lpv.gather(C, f, V, o, not split)
  frame.lpv = { V = V, o = o } -- for passes that read the volumes too (lpv.bind: glossy, transparent)
  return { C = C, E = isr.blur(E, C, f, o.blur), k = o.k }
end

return lpv
