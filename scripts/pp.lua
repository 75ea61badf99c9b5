-- The default pipeline. Techniques follow the seed viewer's modes; the first
-- one listed is the default. Options are what `limn capture --set` can change.
local gbuffer = require "gbuffer"
local isr = require "isr"
local rsm = require "rsm"
local vpl = require "vpl"
local lpv = require "lpv"
local temporal = require "temporal"
local shadow = require "shadow"
local sky = require "sky"
local ssdo = require "ssdo"
local ssao = require "ssao"
local post = require "post"
local options = require "options"
local reflections = require "reflections"

-- The seed's viewer modes: isr+esm (F2, the default), isr (F3), dl+esm (F4),
-- dl (F5); then screen-space directional and ambient occlusion (seed 001).
-- "+esm" turns shadows on; shadow.technique picks their filter. rsm+esm:
-- indirect light from reflective shadow maps (seed 004, scripts/rsm.lua);
-- vpl+esm: indirect point lights and negative lights in them (seed 002,
-- scripts/vpl.lua); isr+rsm+esm: RSM and ISR together, each sender counted
-- once (docs/gi-combined.md); lpv+esm: light propagation volumes (seed 003,
-- scripts/lpv.lua); isr+lpv+esm: LPV and ISR together, as isr+rsm+esm.
Techniques = { "isr+esm", "isr", "dl+esm", "dl", "ssdo+esm", "ssdo", "ssao+esm", "ssao", "rsm+esm",
               "vpl+esm", "isr+rsm+esm", "lpv+esm", "isr+lpv+esm" }

Options = {
  ambient = 0.02,          -- ambient light L_a (grey), scaled by each material's k_a
  background = 0.0,        -- radiance where no geometry is
  materials = "phong",     -- "phong" (the std technique) or "pbr" (glTF metallic-roughness, GGX)
  light_variants = 12,     -- lighting passes compile a variant for the scene's light set when it has at
                           -- most this many lights (0..16), each light evaluated for its kind alone;
                           -- more lights, or 0, take the general loop over the light grid (which culls
                           -- lights of small reach: office with 9 more such lights, the two cost alike)
  isr = {},                -- see isr.defaults in scripts/isr.lua
  rsm = {},                -- see rsm.defaults in scripts/rsm.lua
  vpl = {},                -- see vpl.defaults in scripts/vpl.lua
  lpv = {},                -- see lpv.defaults in scripts/lpv.lua
  shadow = {},             -- see shadow.defaults in scripts/shadow.lua
  sky = {},                -- see sky.defaults in scripts/sky.lua (off by default)
  ssdo = {},               -- see ssdo.defaults in scripts/ssdo.lua
  ssao = {},               -- see ssao.defaults in scripts/ssao.lua
  reflections = {},        -- see reflections.defaults in scripts/reflections.lua
}
for k, v in pairs(isr.defaults) do Options.isr[k] = v end
for k, v in pairs(rsm.defaults) do Options.rsm[k] = v end
for k, v in pairs(vpl.defaults) do Options.vpl[k] = v end
for k, v in pairs(lpv.defaults) do Options.lpv[k] = v end
for k, v in pairs(shadow.defaults) do Options.shadow[k] = v end
for k, v in pairs(sky.defaults) do Options.sky[k] = v end
for k, v in pairs(ssdo.defaults) do Options.ssdo[k] = v end
for k, v in pairs(ssao.defaults) do Options.ssao[k] = v end
for k, v in pairs(reflections.defaults) do Options.reflections[k] = v end
-- Post effects, each off by default (the seed viewer's F6 bloom, F7 dof, F8
-- glass, F9 radial_blur, F11 sepia, F12 tiles; and hdr, motion_blur): a
-- table per effect, `--set bloom=true` turns one on (bloom.enabled), and
-- `--set dof.focus=3.5` sets a parameter. See scripts/post.lua.
for name, d in pairs(post.defaults()) do Options[name] = d end

local function grey(x) return { x, x, x } end

-- The frame's direct light, computed once: the dl techniques' result (with
-- the ambient term); with `indirect` (rsm, lpv: { C, E, k }) also the
-- indirect light, upsampled (direct.frag's INDIRECT); or, for the
-- screen-space GI techniques, the lights alone (ambient 0: their composite
-- adds the ambient term, occluded, and the indirect light), which also
-- serves as their senders' radiance.
local function direct(G, tech, shadows, ambient, name, skylight, indirect)
  local inputs, defines = shadow.bind(shadows, gbuffer.inputs(G), gbuffer.defines(G, {}))
  local params = sky.bind(skylight, { ambient = grey(ambient), background = grey(tech.background) }, defines)
  if indirect then
    isr.bind_coarse(inputs, defines, indirect.C, indirect.E)
    defines.INDIRECT, params.k = true, indirect.k
  end
  return pass{ "direct", shader = "direct.frag", inputs = inputs, defines = defines,
               fetches = not shadows and 4 or nil, -- the G-buffer; shadow lookups vary with the lights
               params = params,
               out = target{ name, format = "rgba16f" } }
end

-- Does the frame read the G-buffer's velocity (motion blur, unless nothing
-- moved since the last frame: scripts/motion_blur.lua; or the temporal reuse
-- of the technique's lighting)? A frame that does not declares none.
local function reads_velocity(tech, lighting)
  local gi = ({ isr = tech.isr, rsm = tech.rsm, ssdo = tech.ssdo })[lighting]
  local function on(t) return type(t) == "table" and t.enabled == true end
  return (on(tech.motion_blur) and still_frames() == 0) or
         (gi ~= nil and on(gi.temporal) and gi.temporal.velocity ~= false)
end

local rules = { ambient = options.number(0, 1e6), background = options.number(0, 1e6),
                light_variants = options.whole(0, 16) }

function OnCreate()
  post.create()
  temporal.create("rsm", { 1, 2, 3, 4 })       -- rsm.temporal's, at each coarse factor (one is made)
  temporal.create("isr", { 1, 2, 3, 4 }, { view = true, keep = true }) -- isr.temporal's, at each coarse
                                                                       -- factor (one is made)
  temporal.create("ssdo", { 1, 2, 4 }, { view = true })                -- ssdo.temporal's, at each resolution
end

function OnRender(tech)
  for _, k in ipairs{ "ambient", "background", "light_variants" } do
    local want = rules[k](tech[k])
    if want then error(string.format("%s must be %s (got %s)", k, want, tostring(tech[k])), 2) end
  end
  -- What the GI histories depend on (temporal.lua): a change starts them again.
  temporal.begin{ tech.name, tech.ambient, tech.background, tech.materials, tech.isr, tech.rsm, tech.vpl,
                  tech.lpv, tech.shadow, tech.sky, tech.ssdo }
  local lighting = tech.name:match("^[^+]*")
  if tech.name:find("+esm", 1, true) and lighting == "ssdo" and tech.ssdo.variant == "two_step" then
    error('ssdo+esm cannot take ssdo.variant = "two_step" (it relights without shadows)')
  end
  local materials = ({ phong = "std", pbr = "pbr" })[tech.materials]
  if not materials then error('materials must be "phong" or "pbr" (got "' .. tostring(tech.materials) .. '")') end
  local G = gbuffer.render(gbuffer.targets(1, materials, reads_velocity(tech, lighting)), materials)
  G.lights = light_set(tech.light_variants) -- nil: the general light loop (gbuffer.defines)
  temporal.velocity(G.vel)
  -- Shadows after the G-buffer: their cascades fit the depths it sees.
  -- The RSM's options, when the technique reads one (the shadow pass then writes it).
  local o_rsm = lighting == "vpl" and vpl.check(tech.vpl) or tech.name:find("rsm+", 1, true) and rsm.check(tech.rsm)
                or tech.name:find("lpv+", 1, true) and lpv.check(tech.lpv)
  local shadows, R
  if tech.name:find("+esm", 1, true) then shadows, R = shadow.render(tech.shadow, G, o_rsm) end
  if shadows and tech.shadow.debug then return present(shadow.debug(shadows)) end
  local lit
  local skylight = sky.light(tech.sky) -- nil when off: then nothing of it is recorded
  if lighting == "dl" or (lighting == "rsm" or lighting == "vpl" or lighting == "lpv") and not R then -- no caster: no RSM
    lit = direct(G, tech, shadows, tech.ambient, "lit", skylight)
  elseif lighting == "vpl" then -- its full-size refinement lights the pixel too
    lit = vpl.render(G, shadows, R, o_rsm, { ambient = grey(tech.ambient), background = grey(tech.background),
                                             sky = skylight })
  elseif lighting == "rsm" or lighting == "lpv" then
    -- Off-screen indirect light needs no direct light of this frame: the direct pass adds it.
    local indirect = lighting == "rsm" and rsm.indirect(G, shadows, R, o_rsm) or lpv.indirect(G, R, o_rsm)
    lit = direct(G, tech, shadows, tech.ambient, "lit", skylight, indirect)
  else
    -- The combined techniques count each sender once (docs/gi-combined.md): isr+lpv+esm adds the
    -- light of the senders the camera does not see to the direct light, where ISR's senders send it on;
    -- isr+rsm+esm gathers it in ISR's first march, whose next step sends it on. ISR adds those it sees.
    local light = { ambient = grey(tech.ambient), background = grey(tech.background), sky = skylight }
    local offscreen
    if lighting == "isr" and R and tech.name:find("lpv+", 1, true) then
      offscreen = lpv.indirect(G, R, o_rsm, true)
    elseif lighting == "isr" and R then
      if o_rsm.temporal.enabled then
        error("isr+rsm+esm takes temporal reuse from isr.temporal (one pass gathers both); rsm.temporal is rsm+esm's")
      end
      light.rsm = { coarse = o_rsm.coarse, bind = function(inputs, defines, params, f, temporal_on)
        params.rsm_k = o_rsm.k
        return rsm.bind(inputs, defines, params, R, shadows, o_rsm, f, temporal_on, true)
      end }
    end
    local d = direct(G, tech, shadows, 0, "direct", nil, offscreen)
    if lighting == "isr" then
      lit = isr.render(G, d, tech.isr, light)
    elseif lighting == "ssdo" then
      lit = ssdo.render(G, d, tech.ssdo, light)
    else
      lit = ssao.render(G, d, tech.ssao, light)
    end
  end
  if G.emi then -- emitted light, after the lighting that never sees it
    lit = pass{ "emissive", shader = "bloom_add.frag", inputs = { src = lit, bloom = G.emi },
                out = target{ "lit.emissive", format = "rgba16f" } }
  end
  -- Ray-traced reflections on every technique, left out where no material reflects.
  if tech.reflections.enabled and scene_reflective() then
    lit = reflections.render(G, lit, tech.reflections, { ambient = grey(tech.ambient),
                             background = grey(tech.background), shadows = shadows, sky = skylight })
  end
  present(post.render(lit, tech, G))
end
