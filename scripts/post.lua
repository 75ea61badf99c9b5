-- The post-processing chain over a lit image, in a fixed order:
--   motion_blur, dof           scene-referred (HDR), as a camera would blur
--   bloom                      added before tone mapping (seed 001)
--   hdr                        tone mapping with eye adaptation
--   radial_blur, glass, tiles, sepia    display-referred stylization
-- Each effect is a module as scripts/README.md says (`defaults`, `check`,
-- `render(src, o, frame)`); an effect whose `enabled` is false records no
-- pass. Any pipeline can use the chain (post.render) or the modules one by one.
-- With hdr on, bloom's glow goes to hdr, which adds it as it reads the image:
-- the same picture without a full-size pass that writes the sum. So does
-- depth of field's composite at half size (dof.render's fold): tone mapping
-- and hdr's meter lay the blur over the image at the pixels they read,
-- bloom's bright pass reads it at the reduced size. post.fold = false records
-- each effect's passes as the modules one by one would (tests compare them).
local options = require "options"

local post = {}

post.order = { "motion_blur", "dof", "bloom", "hdr", "radial_blur", "glass", "tiles", "sepia" }
post.fold = true

local modules = {}
for _, name in ipairs(post.order) do modules[name] = require(name) end

-- A fresh table of every effect's defaults, { bloom = { enabled = false, ... }, ... }.
function post.defaults()
  local d = {}
  for _, name in ipairs(post.order) do d[name] = options.copy(modules[name].defaults) end
  return d
end

-- Declares the effects' lasting targets; call from OnCreate.
function post.create()
  modules.hdr.create()
end

-- Records the chain over `lit` with o = { bloom = {...}, dof = {...}, ... }
-- (missing tables take the defaults) and the frame (frame.G, the G-buffer,
-- for dof and motion_blur). Returns the final target and what it holds,
-- present()'s second argument: "display" once hdr tone mapped it, else
-- "scene" (pre-exposed radiance, as `lit`).
function post.render(lit, o, frame)
  o = o or {}
  local tone_mapped = modules.hdr.check(o.hdr, 2).enabled
  local img, glow = lit, nil
  for _, name in ipairs(post.order) do
    if name == "bloom" and tone_mapped then glow = modules.bloom.glow(img, o.bloom)
    elseif name == "dof" then img = modules.dof.render(img, o.dof, frame, tone_mapped and post.fold)
    else img = modules[name].render(img, o[name], frame, name == "hdr" and glow or nil) end
  end
  return img, tone_mapped and "display" or "scene"
end

return post
