-- The default pipeline. Techniques follow the seed viewer's modes; the first
-- one listed is the default. Options are what `limn capture --set` can change.
local gbuffer = require "gbuffer"
local isr = require "isr"
local post = require "post"

-- dl: direct light alone (the seed's F5); isr: image-space radiosity (F3).
Techniques = { "dl", "isr" }

Options = {
  ambient = 0.02,          -- ambient light L_a (grey), scaled by each material's k_a
  background = 0.0,        -- radiance where no geometry is
  isr = {},                -- see isr.defaults in scripts/isr.lua
}
for k, v in pairs(isr.defaults) do Options.isr[k] = v end
-- Post effects, each off by default (the seed viewer's F6 bloom, F7 dof, F8
-- glass, F9 radial_blur, F11 sepia, F12 tiles; and hdr, motion_blur): a
-- table per effect, `--set bloom=true` turns one on (bloom.enabled), and
-- `--set dof.focus=3.5` sets a parameter. See scripts/post.lua.
for name, d in pairs(post.defaults()) do Options[name] = d end

local function grey(x) return { x, x, x } end

-- Direct light alone (the seed's F5 mode).
local function direct(G, tech)
  local lit = target{ "lit", format = "rgba16f" }
  return pass{ "direct", shader = "direct.frag", inputs = gbuffer.inputs(G),
               params = { ambient = grey(tech.ambient), background = grey(tech.background) },
               out = lit }
end

function OnCreate()
  post.create()
end

function OnRender(tech)
  local G = gbuffer.render(gbuffer.targets())
  local lit
  if tech.name == "isr" then
    lit = isr.render(G, tech.isr, { ambient = grey(tech.ambient), background = grey(tech.background) })
  else
    lit = direct(G, tech)
  end
  present(post.render(lit, tech, G))
end
