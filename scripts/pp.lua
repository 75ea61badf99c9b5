-- The default pipeline. Techniques follow the seed viewer's modes; the first
-- one listed is the default. Options are what `limn capture --set` can change.
local gbuffer = require "gbuffer"
local isr = require "isr"
local ssdo = require "ssdo"
local ssao = require "ssao"

-- dl: direct light alone (the seed's F5); isr: image-space radiosity (F3).
-- ssdo, ssao: screen-space directional / ambient occlusion (seed 001).
Techniques = { "dl", "isr", "ssdo", "ssao" }

Options = {
  ambient = 0.02,          -- ambient light L_a (grey), scaled by each material's k_a
  background = 0.0,        -- radiance where no geometry is
  isr = {},                -- see isr.defaults in scripts/isr.lua
  ssdo = {},               -- see ssdo.defaults in scripts/ssdo.lua
  ssao = {},               -- see ssao.defaults in scripts/ssao.lua
}
for k, v in pairs(isr.defaults) do Options.isr[k] = v end
for k, v in pairs(ssdo.defaults) do Options.ssdo[k] = v end
for k, v in pairs(ssao.defaults) do Options.ssao[k] = v end

local function grey(x) return { x, x, x } end

-- Direct light alone (the seed's F5 mode).
local function direct(G, tech)
  local lit = target{ "lit", format = "rgba16f" }
  return pass{ "direct", shader = "direct.frag", inputs = gbuffer.inputs(G),
               params = { ambient = grey(tech.ambient), background = grey(tech.background) },
               out = lit }
end

function OnRender(tech)
  local G = gbuffer.render(gbuffer.targets())
  if tech.name == "isr" then
    present(isr.render(G, tech.isr, { ambient = grey(tech.ambient), background = grey(tech.background) }))
  elseif tech.name == "ssdo" then
    present(ssdo.render(G, direct(G, tech), tech.ssdo, { ambient = grey(tech.ambient) }))
  elseif tech.name == "ssao" then
    present(ssao.render(G, direct(G, tech), tech.ssao))
  else
    present(direct(G, tech))
  end
end
