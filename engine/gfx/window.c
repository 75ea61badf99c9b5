/* A window for the viewer through GLFW: an OpenGL 4.5 core context, key
 * presses as names, mouse drags. One window per process. */
#include "gfx/gfx.h"

#define GLFW_INCLUDE_NONE /* GL comes through epoxy in the rest of gfx */
#include <GLFW/glfw3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { KEY_QUEUE = 64 };

struct lm_window {
  GLFWwindow *glfw;
  int queue[KEY_QUEUE]; /* GLFW key codes pressed, oldest first */
  int head, count;
  double last_x, last_y;
  bool dragging;
  /* The cursor and the framebuffer's size as GLFW's events last told them:
   * asking would be a round trip to the X server every frame (XQueryPointer,
   * XGetWindowAttributes), each a wait for its process on a loaded machine. */
  double cursor_x, cursor_y;
  int width, height;
  bool size_asked; /* a resize of ours is on its way: ask the server once */
};

static const struct {
  const char *name;
  int key;
} named_keys[] = {
    {"Tab", GLFW_KEY_TAB},          {"Escape", GLFW_KEY_ESCAPE},      {"Space", GLFW_KEY_SPACE},
    {"PageUp", GLFW_KEY_PAGE_UP},   {"PageDown", GLFW_KEY_PAGE_DOWN}, {"Home", GLFW_KEY_HOME},
    {"End", GLFW_KEY_END},          {"Left", GLFW_KEY_LEFT},          {"Right", GLFW_KEY_RIGHT},
    {"Up", GLFW_KEY_UP},            {"Down", GLFW_KEY_DOWN},          {"Enter", GLFW_KEY_ENTER},
    {"Backspace", GLFW_KEY_BACKSPACE},
};

static bool key_name(int key, char *out, size_t cap) {
  if (key >= GLFW_KEY_A && key <= GLFW_KEY_Z) return snprintf(out, cap, "%c", 'A' + key - GLFW_KEY_A), true;
  if (key >= GLFW_KEY_0 && key <= GLFW_KEY_9) return snprintf(out, cap, "%c", '0' + key - GLFW_KEY_0), true;
  if (key >= GLFW_KEY_F1 && key <= GLFW_KEY_F12) return snprintf(out, cap, "F%d", 1 + key - GLFW_KEY_F1), true;
  for (size_t i = 0; i < sizeof named_keys / sizeof *named_keys; i++)
    if (named_keys[i].key == key) return snprintf(out, cap, "%s", named_keys[i].name), true;
  return false;
}

static int key_code(const char *name) {
  if (name[0] && !name[1]) {
    if (name[0] >= 'A' && name[0] <= 'Z') return GLFW_KEY_A + name[0] - 'A';
    if (name[0] >= '0' && name[0] <= '9') return GLFW_KEY_0 + name[0] - '0';
  }
  if (name[0] == 'F' && name[1]) {
    int n = atoi(name + 1);
    if (n >= 1 && n <= 12) return GLFW_KEY_F1 + n - 1;
  }
  for (size_t i = 0; i < sizeof named_keys / sizeof *named_keys; i++)
    if (!strcmp(named_keys[i].name, name)) return named_keys[i].key;
  return GLFW_KEY_UNKNOWN;
}

static void on_key(GLFWwindow *glfw, int key, int scancode, int action, int mods) {
  (void)scancode, (void)mods;
  lm_window *w = glfwGetWindowUserPointer(glfw);
  if (action != GLFW_PRESS || w->count == KEY_QUEUE) return; /* a full queue drops keys */
  w->queue[(w->head + w->count++) % KEY_QUEUE] = key;
}

static void on_cursor(GLFWwindow *glfw, double x, double y) {
  lm_window *w = glfwGetWindowUserPointer(glfw);
  w->cursor_x = x, w->cursor_y = y;
}

static void on_cursor_enter(GLFWwindow *glfw, int entered) {
  lm_window *w = glfwGetWindowUserPointer(glfw);
  if (!entered && !w->dragging) w->cursor_x = w->cursor_y = -1; /* outside (a drag still reports motion) */
}

static void on_framebuffer_size(GLFWwindow *glfw, int width, int height) {
  lm_window *w = glfwGetWindowUserPointer(glfw);
  w->width = width, w->height = height;
}

static char glfw_message[512];
static void on_error(int code, const char *message) {
  snprintf(glfw_message, sizeof glfw_message, "GLFW error 0x%x: %s", code, message);
}

lm_window *lm_window_create(const char *title, int width, int height, lm_error *err) {
  glfwSetErrorCallback(on_error);
  if (!glfwInit()) {
    lm_error_set(err, "no window system (%s); is DISPLAY set? (tests use xvfb-run)",
                 glfw_message[0] ? glfw_message : "glfwInit failed");
    return NULL;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  GLFWwindow *glfw = glfwCreateWindow(width, height, title, NULL, NULL);
  if (!glfw) {
    lm_error_set(err, "no OpenGL 4.5 core window: %s", glfw_message[0] ? glfw_message : "unknown reason");
    glfwTerminate();
    return NULL;
  }
  glfwMakeContextCurrent(glfw);
  glfwSwapInterval(1);
  if (!lm_context_adopt_current(err)) {
    glfwDestroyWindow(glfw);
    glfwTerminate();
    return NULL;
  }
  lm_window *w = lm_alloc(sizeof *w);
  w->glfw = glfw;
  glfwSetWindowUserPointer(glfw, w);
  glfwSetKeyCallback(glfw, on_key);
  /* Set before the panel's library chains its own in front of them. */
  glfwSetCursorPosCallback(glfw, on_cursor);
  glfwSetCursorEnterCallback(glfw, on_cursor_enter);
  glfwSetFramebufferSizeCallback(glfw, on_framebuffer_size);
  glfwGetCursorPos(glfw, &w->cursor_x, &w->cursor_y);
  glfwGetFramebufferSize(glfw, &w->width, &w->height);
  return w;
}

void lm_window_destroy(lm_window *w) {
  if (!w) return;
  glfwMakeContextCurrent(NULL);
  glfwDestroyWindow(w->glfw);
  /* Closing the display joins the driver's threads and unloads it: keep it
   * mapped for LeakSanitizer (lm_keep_drivers_loaded). */
  lm_keep_drivers_loaded();
  glfwTerminate();
  free(w);
}

bool lm_window_should_close(const lm_window *w) { return glfwWindowShouldClose(w->glfw); }
void lm_window_poll(lm_window *w) { (void)w, glfwPollEvents(); }
void lm_window_swap(lm_window *w) { glfwSwapBuffers(w->glfw); }
void lm_window_size(lm_window *w, int *width, int *height) {
  if (w->size_asked) glfwGetFramebufferSize(w->glfw, &w->width, &w->height); /* after our resize request */
  w->size_asked = false;
  *width = w->width, *height = w->height;
}
void lm_window_resize(lm_window *w, int width, int height) {
  glfwSetWindowSize(w->glfw, width, height);
  w->size_asked = true;
}

bool lm_window_next_key(lm_window *w, char *name, size_t cap) {
  while (w->count > 0) {
    int key = w->queue[w->head];
    w->head = (w->head + 1) % KEY_QUEUE;
    w->count--;
    if (key_name(key, name, cap)) return true;
  }
  return false;
}

bool lm_window_key_down(const lm_window *w, const char *name) {
  int key = key_code(name);
  return key != GLFW_KEY_UNKNOWN && glfwGetKey(w->glfw, key) == GLFW_PRESS;
}

void lm_window_mouse_drag(lm_window *w, double *dx, double *dy) {
  double x = w->cursor_x, y = w->cursor_y;
  bool down = glfwGetMouseButton(w->glfw, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
  *dx = down && w->dragging ? x - w->last_x : 0;
  *dy = down && w->dragging ? y - w->last_y : 0;
  w->dragging = down;
  w->last_x = x, w->last_y = y;
}

void lm_window_cursor(const lm_window *w, double *x, double *y) { *x = w->cursor_x, *y = w->cursor_y; }
void *lm_window_handle(lm_window *w) { return w->glfw; }
