/* Headless contexts through EGL: the device platform when it offers a
 * hardware device (NVIDIA), else Mesa's surfaceless platform (llvmpipe). */
#define _GNU_SOURCE /* dl_iterate_phdr, RTLD_NODELETE */
#include "gfx/gfx.h"

#include <dlfcn.h>
#include <link.h>

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <stdio.h>
#include <string.h>

static struct {
  EGLDisplay display;
  EGLContext context;
  const char *platform;
} ctx = {EGL_NO_DISPLAY, EGL_NO_CONTEXT, "none"};

static bool has_ext(const char *list, const char *name) {
  size_t n = strlen(name);
  for (const char *p = list; p && (p = strstr(p, name)); p += n)
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

/* First EGL device that is not a software renderer, or EGL_NO_DISPLAY. */
static EGLDisplay device_display(void) {
  EGLDeviceEXT devices[16];
  EGLint count = 0;
  if (!eglQueryDevicesEXT(16, devices, &count)) return EGL_NO_DISPLAY;
  for (EGLint i = 0; i < count; i++) {
    const char *ext = eglQueryDeviceStringEXT(devices[i], EGL_EXTENSIONS);
    if (has_ext(ext, "EGL_MESA_device_software")) continue;
    EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], NULL);
    if (d != EGL_NO_DISPLAY) return d;
  }
  return EGL_NO_DISPLAY;
}

static bool make_context(EGLDisplay d, lm_error *err) {
  EGLint major, minor;
  if (!eglInitialize(d, &major, &minor)) {
    lm_error_set(err, "EGL: eglInitialize failed (0x%x)", eglGetError());
    return false;
  }
  const char *ext = eglQueryString(d, EGL_EXTENSIONS);
  if (!has_ext(ext, "EGL_KHR_surfaceless_context") || !has_ext(ext, "EGL_KHR_no_config_context")) {
    lm_error_set(err, "EGL: the display lacks EGL_KHR_surfaceless_context or EGL_KHR_no_config_context");
    eglTerminate(d);
    return false;
  }
  if (!eglBindAPI(EGL_OPENGL_API)) {
    lm_error_set(err, "EGL: desktop OpenGL is not available (eglBindAPI failed)");
    eglTerminate(d);
    return false;
  }
  const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                            EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                            EGL_NONE};
  EGLContext c = eglCreateContext(d, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
  if (c == EGL_NO_CONTEXT) {
    lm_error_set(err, "EGL: no OpenGL 4.5 core context on this display (0x%x)", eglGetError());
    eglTerminate(d);
    return false;
  }
  if (!eglMakeCurrent(d, EGL_NO_SURFACE, EGL_NO_SURFACE, c)) {
    lm_error_set(err, "EGL: eglMakeCurrent failed (0x%x)", eglGetError());
    eglDestroyContext(d, c);
    eglTerminate(d);
    return false;
  }
  ctx.display = d;
  ctx.context = c;
  return true;
}

static void GLAPIENTRY debug_message(GLenum source, GLenum type, GLuint id, GLenum severity,
                                     GLsizei length, const GLchar *message, const void *user) {
  (void)source, (void)id, (void)length, (void)user;
  if (severity == GL_DEBUG_SEVERITY_NOTIFICATION) return;
  lm_log(type == GL_DEBUG_TYPE_ERROR ? LM_LOG_WARN : LM_LOG_DEBUG, "GL: %s", message);
}

bool lm_context_adopt_current(lm_error *err) {
  if (epoxy_gl_version() < 45) {
    lm_error_set(err, "OpenGL 4.5 core is needed; the context offers %s (%s)",
                 (const char *)glGetString(GL_VERSION), (const char *)glGetString(GL_RENDERER));
    return false;
  }
  if (ctx.display == EGL_NO_DISPLAY) ctx.platform = "window";
  return true;
}

bool lm_context_create_headless(const lm_context_desc *desc, lm_error *err) {
  const char *want = desc && desc->platform ? desc->platform : "auto";
  if (strcmp(want, "auto") && strcmp(want, "device") && strcmp(want, "surfaceless")) {
    lm_error_set(err, "unknown EGL platform '%s' (auto, device, surfaceless)", want);
    return false;
  }
  const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!client) {
    lm_error_set(err, "EGL: no EGL client extensions; is libEGL (libegl1, libegl-mesa0) installed?");
    return false;
  }
  lm_error tried = {{0}};
  /* NVIDIA's libEGL lists EGL_EXT_device_base, which holds enumeration and
   * query, instead of EGL_EXT_device_enumeration (seen with driver 580). */
  bool enumerate = has_ext(client, "EGL_EXT_device_enumeration") || has_ext(client, "EGL_EXT_device_base");
  bool device_platform = has_ext(client, "EGL_EXT_platform_device") && enumerate;
  if (strcmp(want, "surfaceless") && device_platform) {
    EGLDisplay d = device_display();
    if (d != EGL_NO_DISPLAY && make_context(d, &tried)) {
      ctx.platform = "egl-device";
      goto ready;
    }
    if (d == EGL_NO_DISPLAY) lm_error_set(&tried, "EGL device platform: no hardware device");
  } else if (!strcmp(want, "device")) {
    lm_error_set(&tried, "EGL: %s is missing", enumerate ? "EGL_EXT_platform_device"
                                                          : "EGL_EXT_device_enumeration (or EGL_EXT_device_base)");
  }
  if (!strcmp(want, "device")) {
    lm_error_set(err, "%s", tried.msg);
    return false;
  }
  if (!has_ext(client, "EGL_MESA_platform_surfaceless")) {
    lm_error_set(err, "EGL: no usable platform (%s; EGL_MESA_platform_surfaceless is missing: install "
                 "libegl-mesa0 and libgl1-mesa-dri)", tried.msg[0] ? tried.msg : "no device platform");
    return false;
  }
  EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
  if (d == EGL_NO_DISPLAY || !make_context(d, err)) {
    if (d == EGL_NO_DISPLAY) lm_error_set(err, "EGL: no surfaceless display");
    return false;
  }
  ctx.platform = "egl-surfaceless";
ready:
  if (!lm_context_adopt_current(err)) {
    lm_context_destroy();
    return false;
  }
  if (desc && desc->debug) {
    glEnable(GL_DEBUG_OUTPUT);
    glDebugMessageCallback(debug_message, NULL);
  }
  return true;
}

/* RTLD_NOLOAD: only one already loaded; RTLD_NODELETE: never unloaded from
 * now on. Drivers only: EGL and GLX dlopen them, so the loader has their
 * search lists; another library, loaded as a dependency, would get one
 * built now, which valgrind counts as lost at exit. */
static int keep_driver(struct dl_phdr_info *info, size_t size, void *user) {
  (void)size, (void)user;
  if (info->dlpi_name && strstr(info->dlpi_name, "/dri/")) dlopen(info->dlpi_name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
  return 0;
}

void lm_keep_drivers_loaded(void) { dl_iterate_phdr(keep_driver, NULL); }

void lm_context_destroy(void) {
  if (ctx.display == EGL_NO_DISPLAY) return;
  eglMakeCurrent(ctx.display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(ctx.display, ctx.context);
  /* Terminating joins llvmpipe's threads, so that nothing of Mesa's runs
   * at exit (LeakSanitizer stops every thread then). It also unloads the
   * driver, whose static allocation (Mesa 22.3) would then look leaked:
   * keep it mapped. The next create initializes the display again. */
  lm_keep_drivers_loaded();
  eglTerminate(ctx.display);
  eglReleaseThread();
  ctx.display = EGL_NO_DISPLAY;
  ctx.context = EGL_NO_CONTEXT;
  ctx.platform = "none";
}

const char *lm_gl_renderer(void) { return (const char *)glGetString(GL_RENDERER); }
const char *lm_gl_version(void) { return (const char *)glGetString(GL_VERSION); }
const char *lm_context_platform(void) { return ctx.platform; }
