-- Ray-traced reflections, the hybrid of seed 003 chapter 6: the GPU writes
-- the reflection rays of reflective pixels at `scale` of the output
-- (reflect_rays.frag), the CPU traces them against the scene's BVH and writes
-- a G-buffer of the hits (the engine's "trace" function, engine/trace), the
-- GPU lights the hits as it lights the camera's view (reflect_light.frag,
-- with shadows), brings them to full size with the geometry-aware upsampling
-- of filters.lua and adds them weighted by each pixel's reflectivity
-- (reflect_apply.frag). One bounce: a mirror seen in a mirror shows unlit.
-- Laid out as scripts/README.md's contract says, so modules read alike.
local filters = require "filters"
local gbuffer = require "gbuffer"
local options = require "options"
local shadow = require "shadow"
local sky = require "sky"

local reflections = {}

reflections.defaults = {
  enabled = false,
  scale = 0.5,          -- 1, 0.5 or 0.25 of the output (the seed: 0.5, a quarter of the pixels)
  max_distance = 0,     -- longest reflection ray, world units; 0: unlimited
  sigma_depth = 0.02,   -- upsampling: distance off the plane, share of the depth
  sigma_normal = 0.2,   -- upsampling: 1 - cos of the normals' angle
}

local rules = {
  enabled = options.boolean,
  scale = options.one_of(1, 0.5, 0.25),
  max_distance = options.number(0, 1e30),
  sigma_depth = options.number(1e-6, 1e6),
  sigma_normal = options.number(1e-6, 1e6),
}

reflections.check = options.checker("reflections", reflections.defaults, rules)

-- Adds reflections to `lit` (full size) for frame.G with options o, lit as
-- the camera's view is (frame.light = { ambient =, background =, sky = },
-- frame.shadows). Returns a full-size rgba16f target "reflect.out".
function reflections.render(lit, o, frame)
  local G, light = frame.G, frame.light
  o = reflections.check(o, 2)
  local f = math.floor(1 / o.scale + 0.5)
  local function half(name, format) return target{ name, format = format, scale = 1 / f } end
  local rays_o, rays_d = half("reflect.rays_o", "rgba32f"), half("reflect.rays_d", "rgba32f")
  pass{ "reflect.rays", shader = "reflect_rays.frag", inputs = { nrm = G.nrm, dpt = G.dpt, mat = G.mat },
        params = { factor = f, max_distance = o.max_distance }, out = { rays_o, rays_d } }
  local H = { clr = half("reflect.hit_clr", "rgba8"), nrm = half("reflect.hit_nrm", "rgba16f"),
              pos = half("reflect.hit_pos", "rgba32f"), mat = half("reflect.hit_mat", "rgba8") }
  cpu{ "reflect.trace", fn = "trace", inputs = { rays_o = rays_o, rays_d = rays_d },
       out = { H.clr, H.nrm, H.pos, H.mat } }
  local inputs, defines = shadow.bind(frame.shadows, { hit_clr = H.clr, hit_nrm = H.nrm, hit_pos = H.pos,
                                                       hit_mat = H.mat, rays_o = rays_o, rays_d = rays_d },
                                       gbuffer.lights(frame.G, {}))
  local params = sky.bind(light.sky, { ambient = light.ambient, background = light.background }, defines)
  local refl = pass{ "reflect.light", shader = "reflect_light.frag", inputs = inputs, defines = defines,
                     params = params,
                     out = half("reflect.lit", "rgba16f") }
  refl = filters.upsample(refl, G, { name = "reflect.upsample", format = "rgba16f", factor = f,
                                     sigma_depth = o.sigma_depth, sigma_normal = o.sigma_normal })
  return pass{ "reflect.apply", shader = "reflect_apply.frag", inputs = { lit = lit, refl = refl, mat = G.mat },
               out = target{ "reflect.out", format = "rgba16f" } }
end

return reflections
