-- limn bench's calibration: a pass of a known number of texture fetches a
-- pixel, timed like any other, so passes can be set against the machine.
Techniques = { "calibrate" }
Options = { fetches = 16 }

function OnRender(tech)
  local src = pass{ "calibrate.fill", shader = "calibrate_fill.frag",
                    out = target{ "calibrate.src", format = "rgba16f" } }
  present(pass{ "calibrate", shader = "calibrate.frag", inputs = { src = src },
                params = { count = tech.fetches }, fetches = tech.fetches,
                out = target{ "calibrate.out", format = "rgba16f" } })
end
