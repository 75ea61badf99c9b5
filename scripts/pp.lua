-- The default pipeline. Techniques follow the seed viewer's modes; the first
-- one listed is the default. Options are what `limn capture --set` can change.
local gbuffer = require "gbuffer"
local isr = require "isr"
local shadow = require "shadow"
local ssdo = require "ssdo"
local ssao = require "ssao"
local post = require "post"
local reflections = require "reflections"

-- The seed's viewer modes: isr+esm (F2, the default), isr (F3), dl+esm (F4),
-- dl (F5); then screen-space directional and ambient occlusion (seed 001).
-- "+esm" turns shadows on; shadow.technique picks their filter.
Techniques = { "isr+esm", "isr", "dl+esm", "dl", "ssdo+esm", "ssdo", "ssao+esm", "ssao" }

Options = {
  ambient = 0.02,          -- ambient light L_a (grey), scaled by each material's k_a
  background = 0.0,        -- radiance where no geometry is
  isr = {},                -- see isr.defaults in scripts/isr.lua
  shadow = {},             -- see shadow.defaults in scripts/shadow.lua
  ssdo = {},               -- see ssdo.defaults in scripts/ssdo.lua
  ssao = {},               -- see ssao.defaults in scripts/ssao.lua
  reflections = {},        -- see reflections.defaults in scripts/reflections.lua
}
for k, v in pairs(isr.defaults) do Options.isr[k] = v end
for k, v in pairs(shadow.defaults) do Options.shadow[k] = v end
for k, v in pairs(ssdo.defaults) do Options.ssdo[k] = v end
for k, v in pairs(ssao.defaults) do Options.ssao[k] = v end
for k, v in pairs(reflections.defaults) do Options.reflections[k] = v end
-- Post effects, each off by default (the seed viewer's F6 bloom, F7 dof, F8
-- glass, F9 radial_blur, F11 sepia, F12 tiles; and hdr, motion_blur): a
-- table per effect, `--set bloom=true` turns one on (bloom.enabled), and
-- `--set dof.focus=3.5` sets a parameter. See scripts/post.lua.
for name, d in pairs(post.defaults()) do Options[name] = d end

local function grey(x) return { x, x, x } end

-- Direct light alone (the seed's F4/F5 modes).
local function direct(G, tech, shadows)
  local inputs, defines = shadow.bind(shadows, gbuffer.inputs(G), {})
  return pass{ "direct", shader = "direct.frag", inputs = inputs, defines = defines,
               fetches = not shadows and 4 or nil, -- the G-buffer; shadow lookups vary with the lights
               params = { ambient = grey(tech.ambient), background = grey(tech.background) },
               out = target{ "lit", format = "rgba16f" } }
end

function OnCreate()
  post.create()
end

function OnRender(tech)
  local lighting = tech.name:match("^[^+]*")
  if tech.name:find("+esm", 1, true) and lighting == "ssdo" and tech.ssdo.variant ~= "merged" then
    error('ssdo+esm needs ssdo.variant = "merged" (the two-step variant relights without shadows)')
  end
  local G = gbuffer.render(gbuffer.targets())
  -- Shadows after the G-buffer: their cascades fit the depths it sees.
  local shadows = tech.name:find("+esm", 1, true) and shadow.render(tech.shadow, G) or nil
  if shadows and tech.shadow.debug then return present(shadow.debug(shadows)) end
  local lit
  if lighting == "isr" then
    lit = isr.render(G, tech.isr, { ambient = grey(tech.ambient), background = grey(tech.background),
                                    shadows = shadows })
  elseif lighting == "ssdo" then
    lit = ssdo.render(G, direct(G, tech, shadows), tech.ssdo, { ambient = grey(tech.ambient) })
  elseif lighting == "ssao" then
    lit = ssao.render(G, direct(G, tech, shadows), tech.ssao)
  else
    lit = direct(G, tech, shadows)
  end
  -- Ray-traced reflections on every technique, left out where no material reflects.
  if tech.reflections.enabled and scene_reflective() then
    lit = reflections.render(G, lit, tech.reflections, { ambient = grey(tech.ambient),
                             background = grey(tech.background), shadows = shadows })
  end
  present(post.render(lit, tech, G))
end
