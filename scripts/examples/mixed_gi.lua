-- Tutorial 2: a technique that mixes two GI modules, added to the default
-- pipeline as one row and nothing else. lpv.lua brings the light of the
-- senders (seen or not) through light propagation volumes, which the direct
-- pass adds; ssao.lua then darkens the ambient term where occluders hide it.
-- pp.lua builds its frames from the row, `limn capture --list-options` lists
-- it and the viewer gives it F10.
--   limn capture --script scripts/examples/mixed_gi.lua --tech lpv+ssao+esm --output mixed.png
require "pp"
local technique = require("techniques").add

technique{ "lpv+ssao+esm", lighting = "ssao", shadows = true, offscreen = "lpv", key = "F10" }
