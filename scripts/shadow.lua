-- Shadow maps for every light that casts shadows. The engine plans the tiles
-- (engine/shadow: cascades for directional lights, one tile for a spot, six
-- cube faces for a point light, all in one atlas); this module records the
-- passes: depth from each light, then for ESM a separable blur in log space.
-- Lighting shaders read the atlas through shaders/shadow.glsl.
local options = require "options"

local shadow = {}

-- The options a pipeline exposes (pp.lua's Options.shadow), with defaults.
shadow.defaults = {
  technique = "esm",  -- "esm" (seed 000 eq 30), "pcf" (3x3), "poisson" (16 taps), "hard",
                      -- "pcss" (soft shadows whose penumbra grows with the blocker's distance, seed 003)
  resolution = 512,   -- tile size in texels, 16..8192 (the seed: 512)
  c = 16,             -- ESM exponent per texel of depth: exp(-c d), d in texels' world size where
                      -- the receiver is (the seed's 90 on the light's range is ~0.2 a texel at 512:
                      -- light leaks over tens of texels behind every occluder)
  blur = 0,           -- ESM log-space Gaussian radius in texels, 0..32 (the seed: 2); at large c a
                      -- blur lights a band of its radius beside every occluder's edge
  cascades = 3,       -- directional lights, 1..4
  lambda = 0.75,      -- cascade splits: 0 uniform .. 1 logarithmic
  bias = 1,           -- depth bias in texels: the world size of a shadow-map texel where the
                      -- receiver is, 0..64 (the seed: 0 for ESM, which darkens lit slanted
                      -- surfaces by 1-2%)
  distance = 0,       -- how far cascades reach from the camera, world units (0: as far as
                      -- anything is seen)
  blend = 0.1,        -- share of a cascade blended into the next one
  radius = 2.5,       -- Poisson disc radius in texels
  stabilize = true,   -- bounding spheres and texel snapping (seed 003)
  cache = true,       -- a tile whose view and casters are unchanged since the last frame keeps its
                      -- texels instead of being drawn again (a still camera; spot and point lights)
  coverage = true,    -- spot and point lights' tiles about as fine as the screen needs: a texel a pixel
                      -- over the disc their reach covers on screen, from resolution down to 32 texels
                      -- (false: every tile at resolution)
  size = -1,          -- PCSS: every light's size (its diameter in the scene's unit; for the sun its
                      -- angular diameter, radians); <= 0: each light's own (glTF extras.size, else
                      -- 0.0093 rad for directional lights, 1% of the shadow map's range for others)
  penumbra = 16,      -- PCSS: the widest penumbra radius (and blocker search), texels, 1..64
  fit = "current",    -- cascades fit the depths the G-buffer saw: "current" (this frame's, read back
                      -- when the G-buffer is done: the frame waits for it, 1.8 ms of a 5 ms frame at
                      -- 1080p on a GPU) or "previous" (the last frame's, read without waiting; a
                      -- view's first frame reads its own)
  fit_margin = 0.25,  -- "previous": that range widened by this share each way, 0..10, for what came
                      -- into view since (on still frames too: cascades keep their size when the
                      -- camera starts or stops)
  simplify = 0.5,     -- a caster whose simplified copy (made at load: meshoptimizer, 0.0625% to 16% of
                      -- the mesh's extent) errs by at most this many texels of a tile draws it there:
                      -- far cascades and small tiles draw fewer triangles; 0..64, 0: never
  debug = false,      -- present the shadow atlas instead of the image
}

-- shadow_plan{} checks the rest (engine/script/script_api.c).
local rules = { technique = options.one_of("esm", "pcf", "poisson", "hard", "pcss"),
                fit = options.one_of("current", "previous"), fit_margin = options.number(0, 10) }
shadow.check = options.checker("shadow", shadow.defaults, rules)

-- The depth range's reduction (shadow.depth_range): the first level reads
-- FIRST_BLOCK x FIRST_BLOCK pixels a texel, so that its output spans several
-- of llvmpipe's 64 x 64 tiles, which its threads share (at 8 x 8 a 512x384
-- frame's first level was one tile: one thread read the whole G-buffer);
-- later levels BLOCK x BLOCK.
local FIRST_BLOCK, BLOCK = 4, 16

-- Each atlas's filter as shaders/shadow.glsl numbers them (SHADOW_FILTER:
-- lm_shadow_technique), kept for shadow.bind; weak keys: atlases are per frame.
local FILTERS = { esm = 0, pcf = 1, poisson = 2, hard = 3, pcss = 4 }
local filter_of = setmetatable({}, { __mode = "k" })
local transmit_of = setmetatable({}, { __mode = "k" }) -- atlas -> its blended casters' transmittance

-- The least and greatest camera depth the G-buffer G sees (depth / far in r
-- and g of a 1x1 target), by min/max reduction passes.
function shadow.depth_range(G)
  local w, h = output_size()
  local level, n = G.dpt, 0
  repeat
    local block = n == 0 and FIRST_BLOCK or BLOCK
    w, h, n = (w + block - 1) // block, (h + block - 1) // block, n + 1
    level = pass{ "shadow.range" .. n, shader = "depth_range.frag", inputs = { src = level },
                  defines = { FIRST = n == 1, BLOCK = block },
                  out = target{ "shadow.range" .. n, format = "rg32f", size = { w, h } } }
  until w == 1 and h == 1
  return level
end

-- Records the shadow passes. Returns the atlas a lighting pass reads as
-- `shadow_atlas`, or nil when no light casts shadows (nothing is recorded).
-- With the G-buffer G (recorded before), cascades fit the depths it sees
-- (shadow.depth_range); without, the depths of the meshes in view.
-- With rsm ({ reach =, resolution = }: the checked options of rsm, vpl or lpv), a second scene
-- pass, shadow.rsm, writes reflective shadow maps (seed 004; shadow.frag) over the plan's RSM
-- views alone, into their own atlas (docs/shadows.md "The RSM atlas": every view `resolution`
-- texels a side, shadow_plan's rsm_resolution); returned second as { flux =, nrm =, pos =,
-- views =, seen = } (rsm.frag reads them through the views' records; views: how many RSM views;
-- seen: the depth range G sees, shadow.depth_range, nil without G), and with rsm.solid_steps or
-- rsm.solid_cell above 0 back = shadow.rsm_back, where the first solid on the light's way ends, with
-- rsm.solid_cell solid = shadow.rsm_solid, the solid grid (rsm_solid.frag). A directional light's RSM
-- view is one tile over the sphere around all that is seen, its radius times reach; a spot or
-- point light's are its shadow views. Without, no RSM target or view exists.
-- A scene with blended materials (scene_blended()) gets one more output, shadow.transmit: what
-- its blended casters let through (rgb) beyond their least depth (a), which shadow.bind adds
-- to lighting passes (SHADOW_TRANSMIT, shaders/shadow.glsl): lighter, tinted shadows.
function shadow.render(o, G, rsm)
  o = shadow.check(o, 2)
  local settings = {}
  for k, v in pairs(o) do
    if k ~= "debug" and k ~= "fit" and k ~= "fit_margin" then settings[k] = v end
  end
  if rsm then settings.rsm, settings.rsm_resolution = rsm.reach, rsm.resolution end
  local plan = shadow_plan(settings)
  if not plan then return nil end
  local size = { plan.width, plan.height }
  local map = target{ "shadow.map", format = "r32f", size = size }
  local seen = G and shadow.depth_range(G) or nil
  local transmit = scene_blended() and target{ "shadow.transmit", format = "rgba16f", size = size } or nil
  scene{ "shadow.depth", technique = "shadow", views = plan, fit = seen,
         fit_margin = seen and o.fit == "previous" and o.fit_margin or nil,
         out = { map, transmit }, clear = { 1, 1, 1, 1 }, transmit = transmit,
         defines = { TRANSMIT = transmit and 1 or nil },
         depth = target{ "shadow.zbuffer", format = "depth32f", size = size } }
  local R
  if rsm then
    local rsize = { plan.rsm_width, plan.rsm_height }
    R = { flux = target{ "shadow.rsm_flux", format = "rgba16f", size = rsize },
          nrm = target{ "shadow.rsm_nrm", format = "rgba16f", size = rsize },
          pos = target{ "shadow.rsm_pos", format = "rgba32f", size = rsize },
          views = plan.rsm_views, seen = seen }
    -- After shadow.depth: its fit (seen) places the RSM views too.
    scene{ "shadow.rsm", technique = "shadow", views = plan, rsm = true, fit = seen,
           out = { R.flux, R.nrm, R.pos }, clear = { 1, 1, 1, 1 }, defines = { RSM = true },
           depth = target{ "shadow.rsm_zbuffer", format = "depth32f", size = rsize } }
    local cell = rsm.solid_cell or 0
    if (rsm.solid_steps or 0) > 0 or cell > 0 then
      -- The surfaces the light sees last of the first solid on its way: where a solid ends (shadow.frag's
      -- RSM_BACK), which the gather's rsm_inside_solid reads, and the solid grid is made of.
      R.back = target{ "shadow.rsm_back", format = "rgba32f", size = rsize }
      scene{ "shadow.rsm_back", technique = "shadow", views = plan, rsm = true, fit = seen,
             out = { R.back }, clear = { 1, 1, 1, 1 }, defines = { RSM_BACK = true },
             depth = target{ "shadow.rsm_back_zbuffer", format = "depth32f", size = rsize } }
    end
    if cell > 0 then
      -- Whole cells a tile where its side (shadow.resolution halved) is a multiple of the cell: a power of two.
      R.solid = pass{ "shadow.rsm_solid", shader = "rsm_solid.frag", inputs = { rsm_pos = R.pos, rsm_back = R.back },
                      params = { cell = cell },
                      out = target{ "shadow.rsm_solid", format = "rg32f",
                                    size = { math.max(1, rsize[1] // cell), math.max(1, rsize[2] // cell) } } }
    end
  end
  filter_of[map], transmit_of[map] = FILTERS[plan.technique], transmit
  if plan.technique ~= "esm" or plan.blur == 0 then return map, R end
  local blurred = map
  for _, axis in ipairs{ { "x", { 1, 0 } }, { "y", { 0, 1 } } } do
    blurred = pass{ "shadow.blur_" .. axis[1], shader = "esm_blur.frag", inputs = { shadow_atlas = blurred },
                    params = { direction = axis[2], radius = plan.blur, c = plan.c, views = plan.shadow_views },
                    out = target{ "shadow.esm_" .. axis[1], format = "r32f", size = size } }
  end
  filter_of[blurred], transmit_of[blurred] = filter_of[map], transmit
  return blurred, R
end

-- Adds the atlas to a lighting pass's inputs and defines (no-op without one):
-- SHADOWS, and SHADOW_FILTER, so that the pass compiles the atlas's filter alone.
function shadow.bind(atlas, inputs, defines)
  if atlas then
    inputs.shadow_atlas = atlas
    defines.SHADOWS = true
    defines.SHADOW_FILTER = filter_of[atlas]
    if transmit_of[atlas] then inputs.shadow_transmit, defines.SHADOW_TRANSMIT = transmit_of[atlas], true end
  end
  return inputs, defines
end

-- A viewable image of the atlas: depth as grey, tiles outlined.
function shadow.debug(atlas)
  return pass{ "shadow.debug", shader = "shadow_debug.frag", inputs = { atlas = atlas },
               out = target{ "shadow.debug", format = "rgba8" } }
end

return shadow
