-- The default pipeline: each technique a row, and one function (frame) that
-- records a frame from its row. The first row is the default; Options are
-- what `limn capture --set` can change. Modules follow scripts/README.md.
local direct = require "direct"
local gbuffer = require "gbuffer"
local glossy = require "glossy"
local options = require "options"
local post = require "post"
local reflections = require "reflections"
local shadow = require "shadow"
local sky = require "sky"
local techniques = require "techniques"
local temporal = require "temporal"
local transparent = require "transparent"

Options = {
  ambient = 0.02,          -- ambient light L_a (grey), scaled by each material's k_a
  background = 0.0,        -- radiance where no geometry is
  materials = "phong",     -- "phong" (the std technique) or "pbr" (glTF metallic-roughness, GGX)
  light_variants = 12,     -- up to this many lights (0..16) lighting passes unroll them; more, 0: grid loop
  light_cull = true,       -- yet more than one light and one the grid culls (cone, range): the grid's loop
  front_lit = true,        -- unrolled lights whose shadow tiles hold no face seen from behind skip the shadow
                           -- lookup's second step at a normal offset (the same image; false: every light keeps it)
  simplify = 0.25,         -- a mesh node draws its simplified copy (made at load) that errs by at most this
                           -- many pixels where it comes nearest the camera; 0..64, 0: every mesh whole
  shadow = options.copy(shadow.defaults),
  sky = options.copy(sky.defaults),                -- off by default
  reflections = options.copy(reflections.defaults),
  glossy = options.copy(glossy.defaults),          -- pbr materials' glossy indirect light, off by default
}
-- Post effects, each off by default (the seed viewer's F6 bloom, F7 dof, F8 glass, F9 radial_blur,
-- F11 sepia, F12 tiles; and hdr, motion_blur): `--set bloom=true` turns one on (bloom.enabled),
-- `--set dof.focus=3.5` sets a parameter. See scripts/post.lua.
for name, d in pairs(post.defaults()) do Options[name] = d end

-- Each technique a row (fields: scripts/techniques.lua), its modules' options joining Options: the
-- default first, the seed viewer's modes, then the seeds' GI (docs/gi-combined.md for the combined rows).
local technique = techniques.add
-- The default (the first row) is the technique that removes the most indirect error within about 2x
-- dl+esm's frame at 256x192 with a moving camera (docs/techniques.md#the-default-error-against-time):
-- isr+rsm+esm removes 72.9% of dl+esm's indirect error against POV-Ray and 67.2% against Cycles (the
-- reference set, 160x120) at 1.96-2.10x (three quiet runs of MOTION=1 tools/gi_time.sh), where isr+esm
-- removes 42.1% / 34.4% at 1.6-1.85x and rsm+esm 61.5% / 54.0% at 1.5x. Its RSM is drawn by a pass of
-- its own over 128-texel views, so a moving camera no longer pays the RSM at every cascade tile.
-- Since rsm.bounces 2 (a second bounce over the rays the screen cannot follow) 71.9% / 68.4%: more
-- against Cycles' eight bounces, less against POV-Ray's two (docs/gi-combined.md). Since the RSM
-- gather's pattern turns per 4 x 4 tile (rsm.glsl: one pattern for all biased its mean) 74.6% / 69.3%.
-- Since its unseen senders' visibility (rsm.thickness) and upward rays under a roof counted as unseen
-- 75.7% / 70.2%, Pearson raised in every view against both (docs/gi-combined.md).
technique{ "isr+rsm+esm", lighting = "isr", shadows = true, offscreen = "rsm", joins = "march", split = true,
           temporal = "isr" } -- image-space radiosity with reflective shadow maps (docs/gi-combined.md)
technique{ "isr+esm", lighting = "isr", shadows = true, temporal = "isr", key = "F2" } -- image-space radiosity
technique{ "isr", lighting = "isr", temporal = "isr", key = "F3" }
technique{ "dl+esm", shadows = true, key = "F4" }
technique{ "dl", key = "F5" }
technique{ "ssdo+esm", lighting = "ssdo", shadows = true, temporal = "ssdo" } -- directional occlusion (seed 001)
technique{ "ssdo", lighting = "ssdo", temporal = "ssdo" }
technique{ "ssao+esm", lighting = "ssao", shadows = true } -- ambient occlusion (seed 001)
technique{ "ssao", lighting = "ssao" }
technique{ "rsm+esm", shadows = true, offscreen = "rsm", temporal = "rsm" } -- reflective shadow maps (seed 004)
technique{ "vpl+esm", shadows = true, offscreen = "vpl", joins = "lit" } -- indirect, negative point lights (seed 002)
technique{ "lpv+esm", shadows = true, offscreen = "lpv" } -- light propagation volumes (seed 003)
technique{ "isr+lpv+esm", lighting = "isr", shadows = true, offscreen = "lpv", split = true, temporal = "isr" }

local function grey(x) return { x, x, x } end
-- Records the frame of technique `row` with options `tech`; returns what to present.
local function frame(tech, row)
  local L, S = techniques.modules[row.lighting], techniques.modules[row.offscreen]
  local materials = ({ phong = "std", pbr = "pbr" })[tech.materials]
  if not materials then error('materials must be "phong" or "pbr" (got "' .. tostring(tech.materials) .. '")') end
  local G = gbuffer.render(gbuffer.targets(1, materials, techniques.reads_velocity(tech, row)), materials, nil,
                           tech.simplify)
  G.lights = light_set(tech.light_variants, tech.light_cull, tech.front_lit) -- the light set's defines
                                                                             -- (gbuffer.defines); nil: the
                                                                             -- general loop over storage buffers
  temporal.velocity(G.vel)
  local o = S and S.check(tech[row.offscreen]) -- shadows after the G-buffer: cascades fit what it sees
  local F = { G = G, technique = row, light = { ambient = grey(tech.ambient), background = grey(tech.background) } }
  light_peak(tech.ambient, tech.background) -- light of the frame's own, for the renderer's pre-exposure
  if row.shadows then F.shadows, F.R = shadow.render(tech.shadow, G, o) end
  if F.shadows and tech.shadow.debug then return shadow.debug(F.shadows), "display" end
  F.light.sky = sky.light(tech.sky) -- nil when off: then nothing of it is recorded
  local joins = F.R and S and (row.joins or "direct") -- no caster, no RSM: no off-screen light
  local indirect = joins == "direct" and S.render(nil, o, F) or nil
  if joins == "march" then F.light.rsm = S.march(o, F) end
  local lit = joins == "lit" and S.render(nil, o, F) -- the source lights the frame
              or L and L.render(direct.render(F, 0, "direct", nil, indirect), tech[row.lighting], F)
              or direct.render(F, tech.ambient, "lit", F.light.sky, indirect)
  if G.emi then -- emitted light, after the lighting that never sees it
    lit = pass{ "emissive", shader = "bloom_add.frag", inputs = { src = lit, bloom = G.emi },
                out = target{ "lit.emissive", format = "rgba16f" } }
  end
  -- Ray-traced reflections on every technique, left out where no material reflects.
  if tech.reflections.enabled and scene_reflective() then lit = reflections.render(lit, tech.reflections, F) end
  -- Glossy indirect light for pbr surfaces only: a Phong frame records none of it (its options are
  -- checked on every frame, so a bad one is named while it is off too).
  if glossy.check(tech.glossy, 1).enabled and materials == "pbr" then lit = glossy.render(lit, tech.glossy, F) end
  lit = transparent.render(lit, tech, F) -- blended materials (glass), where the scene has any
  meter(lit) -- its brightness sets the next frame's pre-exposure (tone mapping presents display values)
  return post.render(lit, tech, F)
end

local rules = { ambient = options.number(0, 1e6), background = options.number(0, 1e6),
                light_variants = options.whole(0, 16), light_cull = options.boolean, front_lit = options.boolean,
                simplify = options.number(0, 64),
                materials = options.one_of("phong", "pbr") }
options.declare("", rules) -- the viewer's panel shows each option by its rule

function OnCreate()
  post.create()
  techniques.create()
end

function OnRender(tech)
  options.fields(tech, rules, { "ambient", "background", "light_variants", "light_cull", "front_lit" }, 2)
  -- What the GI histories depend on (temporal.lua): a change starts them again.
  temporal.begin(techniques.settings(tech, { tech.name, tech.ambient, tech.background, tech.materials,
                                             tech.shadow, tech.sky }))
  present(frame(tech, techniques.row(tech.name)))
end
