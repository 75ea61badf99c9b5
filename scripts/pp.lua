-- The default pipeline. Techniques follow the seed viewer's modes; the first
-- one listed is the default. Options are what `limn capture --set` can change.
local gbuffer = require "gbuffer"
local isr = require "isr"
local shadow = require "shadow"

-- The seed's viewer modes: isr+esm (F2, the default), isr (F3), dl+esm (F4),
-- dl (F5). "+esm" turns shadows on; shadow.technique picks their filter.
Techniques = { "isr+esm", "isr", "dl+esm", "dl" }

Options = {
  ambient = 0.02,          -- ambient light L_a (grey), scaled by each material's k_a
  background = 0.0,        -- radiance where no geometry is
  isr = {},                -- see isr.defaults in scripts/isr.lua
  shadow = {},             -- see shadow.defaults in scripts/shadow.lua
}
for k, v in pairs(isr.defaults) do Options.isr[k] = v end
for k, v in pairs(shadow.defaults) do Options.shadow[k] = v end

local function grey(x) return { x, x, x } end

-- Direct light alone (the seed's F4/F5 modes).
local function direct(G, tech, shadows)
  local inputs, defines = shadow.bind(shadows, gbuffer.inputs(G), {})
  return pass{ "direct", shader = "direct.frag", inputs = inputs, defines = defines,
               params = { ambient = grey(tech.ambient), background = grey(tech.background) },
               out = target{ "lit", format = "rgba16f" } }
end

function OnRender(tech)
  local shadows = tech.name:find("+esm", 1, true) and shadow.render(tech.shadow) or nil
  if shadows and tech.shadow.debug then return present(shadow.debug(shadows)) end
  local G = gbuffer.render(gbuffer.targets())
  if tech.name:sub(1, 3) == "isr" then
    present(isr.render(G, tech.isr, { ambient = grey(tech.ambient), background = grey(tech.background),
                                      shadows = shadows }))
  else
    present(direct(G, tech, shadows))
  end
end
