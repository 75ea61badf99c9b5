// The viewer's panel through Dear ImGui (view_panel.h says what it shows).
// A thin bridge: the model comes from C each frame, the edit goes back as
// text that the viewer sets as --set would; nothing here keeps settings.
#include "view_panel.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

struct widget {
  std::string name, kind, group;
  float rect[4]; // x y w h; zero while a closed group hides it
};

struct lm_panel {
  ImGuiContext *context;
  GLFWwindow *window;
  double last_ms;          // the last frame's start, for ImGui's time step
  bool scripted;           // panel_set_mouse took over the mouse
  double mouse[2];
  bool mouse_down;
  std::vector<widget> widgets;     // the last frame's options
  std::vector<widget> techniques;  // and techniques
  std::vector<widget> controls;    // and the buttons and the time slider
  // The panel's image, drawn again only when ImGui's draw lists change: on
  // llvmpipe drawing it costs about as much as a small frame's pass, while
  // compositing a kept image is one texture read in the viewer's display pass.
  lm_texture image;
  int image_w, image_h;
  uint64_t drawn;                  // the draw lists' hash in `image`
  panel_image shown;               // the last frame's
  // Laid out only while something changes: ImGui's frame (new frame,
  // layout, draw lists) is most of an idle panel's cost, and with the same
  // input and model it lays out the same panel.
  uint64_t input, model;           // the last frame's
  int quiet;                       // frames in a row with both the same
  bool graph_open;                 // the frame graph's window was open last frame
};

// The mouse without the GLFW backend's per-frame queries: its NewFrame asks
// the X server for the window's size twice, its focus and the cursor, and
// sets the cursor's shape, every frame (4-5 ms a frame under Xvfb on a loaded
// machine, most of the panel's cost). panel_frame takes the size from the
// viewer, the buttons from GLFW's event state with a press shorter than a
// frame kept by on_button, and the cursor from its motion events (these two
// chained before the backend's callbacks, which feed keys, text and the
// wheel as before). One panel per process: GLFW's callbacks carry no
// pointer of ours.
static GLFWmousebuttonfun chained_button;
static GLFWcursorposfun chained_cursor;
static bool pressed[ImGuiMouseButton_COUNT]; // a press since the last frame
static double cursor[2];

static void on_button(GLFWwindow *w, int button, int action, int mods) {
  if (action == GLFW_PRESS && button >= 0 && button < ImGuiMouseButton_COUNT) pressed[button] = true;
  if (chained_button) chained_button(w, button, action, mods);
}

static void on_cursor(GLFWwindow *w, double x, double y) {
  cursor[0] = x, cursor[1] = y;
  if (chained_cursor) chained_cursor(w, x, y);
}

lm_panel *panel_create(lm_window *w, lm_error *err) {
  IMGUI_CHECKVERSION();
  lm_panel *p = new lm_panel();
  p->context = ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr; // no imgui.ini in the user's folder
  ImGui::StyleColorsDark();
  // Opaque: where its window stands the display composites the panel alone
  // (llvmpipe's cost is per pixel drawn, 10-16 ns of CPU at 640x480).
  ImGui::GetStyle().Colors[ImGuiCol_WindowBg].w = 1.0f;
  // The backends chain GLFW's callbacks: the viewer's key queue still gets every key.
  p->window = static_cast<GLFWwindow *>(lm_window_handle(w));
  bool glfw = ImGui_ImplGlfw_InitForOpenGL(p->window, true);
  if (!glfw || !ImGui_ImplOpenGL3_Init("#version 410 core")) {
    lm_error_set(err, "the panel (Dear ImGui) could not start on this OpenGL context");
    if (glfw) ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext(p->context);
    delete p;
    return nullptr;
  }
  chained_button = glfwSetMouseButtonCallback(p->window, on_button);
  chained_cursor = glfwSetCursorPosCallback(p->window, on_cursor);
  glfwGetCursorPos(p->window, &cursor[0], &cursor[1]); // until it moves
  return p;
}

void panel_destroy(lm_panel *p) {
  if (!p) return;
  lm_texture_destroy(&p->image);
  glfwSetMouseButtonCallback(p->window, chained_button); // the backend's, which its shutdown restores in turn
  glfwSetCursorPosCallback(p->window, chained_cursor);
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext(p->context);
  delete p;
}

void panel_set_mouse(lm_panel *p, double x, double y, bool down) {
  p->scripted = true;
  p->mouse[0] = x, p->mouse[1] = y;
  p->mouse_down = down;
}

bool panel_wants_mouse(const lm_panel *p) { return p && ImGui::GetIO().WantCaptureMouse; }
bool panel_wants_keyboard(const lm_panel *p) { return p && ImGui::GetIO().WantCaptureKeyboard; }

// The widget an option gets: its rule decides, else its value's type.
static const char *widget_kind(const lm_option_info &o) {
  if (o.type == LM_OPTION_OTHER) return "read-only";
  if (o.type == LM_OPTION_BOOLEAN) return "checkbox";
  if (o.rule == LM_RULE_ONE_OF && o.choice_count > 0) return "combo";
  if (o.rule == LM_RULE_COLOUR) return "colour";
  if (o.type == LM_OPTION_NUMBER && o.rule == LM_RULE_WHOLE && std::isfinite(o.hi)) return "slider-int";
  if (o.type == LM_OPTION_NUMBER && o.rule == LM_RULE_NUMBER && std::isfinite(o.hi)) return "slider";
  if (o.type == LM_OPTION_NUMBER) return "drag";
  return "text";
}

// The last item's rectangle as a widget named `name` of `kind`.
static widget last_item(const char *name, const char *kind, const char *group) {
  ImVec2 a = ImGui::GetItemRectMin(), b = ImGui::GetItemRectMax();
  return widget{name, kind, group, {a.x, a.y, b.x - a.x, b.y - a.y}};
}

static void set_edit(panel_edits *e, const char *name, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void set_edit(panel_edits *e, const char *name, const char *fmt, ...) {
  e->option = true;
  snprintf(e->option_name, sizeof e->option_name, "%s", name);
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(e->option_value, sizeof e->option_value, fmt, ap);
  va_end(ap);
}

// One option's widget, labelled by its last name part; an edit goes into *e.
static void option_widget(const lm_option_info &o, const char *kind, panel_edits *e) {
  const char *field = strrchr(o.name, '.') ? strrchr(o.name, '.') + 1 : o.name;
  std::string label = std::string(field) + "##" + o.name;
  double value = atof(o.value);
  if (!strcmp(kind, "read-only")) {
    ImGui::TextDisabled("%s: a %s (not settable here: set it in the script)", field, o.value);
  } else if (!strcmp(kind, "checkbox")) {
    bool b = !strcmp(o.value, "true");
    if (ImGui::Checkbox(label.c_str(), &b)) set_edit(e, o.name, "%s", b ? "true" : "false");
  } else if (!strcmp(kind, "combo")) {
    if (ImGui::BeginCombo(label.c_str(), o.value)) {
      for (int i = 0; i < o.choice_count; i++)
        if (ImGui::Selectable(o.choices[i], !strcmp(o.choices[i], o.value))) set_edit(e, o.name, "%s", o.choices[i]);
      ImGui::EndCombo();
    }
  } else if (!strcmp(kind, "colour")) {
    float c[3] = {0, 0, 0};
    int n = sscanf(o.value, "%f,%f,%f", &c[0], &c[1], &c[2]);
    if (n == 1) c[1] = c[2] = c[0];
    ImGuiColorEditFlags flags = ImGuiColorEditFlags_Float | (o.hi > 1 ? ImGuiColorEditFlags_HDR : 0);
    if (ImGui::ColorEdit3(label.c_str(), c, flags)) {
      for (float &x : c) x = std::fmin(std::fmax(x, 0.0f), static_cast<float>(o.hi));
      set_edit(e, o.name, "%g,%g,%g", c[0], c[1], c[2]);
    }
  } else if (!strcmp(kind, "slider-int")) {
    int step = o.step > 0 ? static_cast<int>(o.step) : 1, lo = static_cast<int>(o.lo);
    int hi = static_cast<int>(std::fmin(o.hi, 1e9)), v = static_cast<int>(value);
    ImGuiSliderFlags flags = ImGuiSliderFlags_AlwaysClamp | (hi - lo > 1000 ? ImGuiSliderFlags_Logarithmic : 0);
    if (ImGui::SliderInt(label.c_str(), &v, lo, hi, "%d", flags)) {
      v = lo + (v - lo) / step * step; // the rule's multiples (odd, multiple)
      set_edit(e, o.name, "%d", v);
    }
  } else if (!strcmp(kind, "slider")) {
    // Wide ranges (0..1e6) slide logarithmically: a linear one would leave
    // every useful value in its first pixel.
    float v = static_cast<float>(value), lo = static_cast<float>(o.lo), hi = static_cast<float>(o.hi);
    bool wide = hi - lo > 100 || (lo > 0 && hi / lo > 100);
    ImGuiSliderFlags flags = ImGuiSliderFlags_AlwaysClamp | (wide ? ImGuiSliderFlags_Logarithmic : 0);
    if (ImGui::SliderFloat(label.c_str(), &v, lo, hi, "%.4g", flags)) set_edit(e, o.name, "%.6g", v);
  } else if (!strcmp(kind, "drag")) {
    // No upper bound (options.positive() or no rule): a drag whose speed follows the value.
    float v = static_cast<float>(value), lo = o.rule == LM_RULE_NONE ? -FLT_MAX : static_cast<float>(o.lo);
    float speed = std::fmax(std::fabs(v) * 0.01f, 0.001f);
    if (ImGui::DragFloat(label.c_str(), &v, speed, lo, FLT_MAX, "%.4g", ImGuiSliderFlags_AlwaysClamp))
      set_edit(e, o.name, "%.6g", v);
  } else { // text, applied on Enter (a file name half typed is no setting); ImGui keeps it while edited
    char buf[256];
    snprintf(buf, sizeof buf, "%s", o.value);
    if (ImGui::InputText(label.c_str(), buf, sizeof buf, ImGuiInputTextFlags_EnterReturnsTrue))
      set_edit(e, o.name, "%s", buf);
  }
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("%s = %s%s", o.name, o.value, o.rule == LM_RULE_NONE ? " (no rule in the script)" : "");
}

// Groups: the first name part (the module), nested tables as tree nodes;
// the pipeline's own options (no dot) under "pipeline".
static std::vector<std::string> groups_of(const char *name) {
  std::vector<std::string> g;
  const char *s = name;
  for (const char *dot; (dot = strchr(s, '.')); s = dot + 1) g.emplace_back(s, dot - s);
  if (g.empty()) g.emplace_back("pipeline");
  return g;
}

static void options_section(lm_panel *p, const panel_model *m, panel_edits *e) {
  p->widgets.assign(m->option_count, widget{});
  std::vector<std::string> path; // groups now open or skipped
  std::vector<bool> shown;        // each level's contents shown
  auto close_to = [&](size_t depth) {
    while (path.size() > depth) {
      if (path.size() > 1 && shown.back()) ImGui::TreePop();
      path.pop_back(), shown.pop_back();
    }
  };
  for (int i = 0; i < m->option_count; i++) {
    const lm_option_info &o = m->options[i];
    std::vector<std::string> g = groups_of(o.name);
    size_t common = 0;
    while (common < path.size() && common < g.size() && path[common] == g[common]) common++;
    close_to(common);
    for (size_t d = path.size(); d < g.size(); d++) {
      bool parent = d == 0 || shown.back(), open = false;
      if (parent && d == 0)
        open = ImGui::CollapsingHeader(g[d].c_str(), g[d] == "pipeline" ? ImGuiTreeNodeFlags_DefaultOpen : 0);
      else if (parent)
        open = ImGui::TreeNode(g[d].c_str());
      path.push_back(g[d]), shown.push_back(open);
    }
    widget &w = p->widgets[i];
    w.name = o.name, w.kind = widget_kind(o), w.group = g[0];
    if (!shown.back()) continue;
    ImGui::PushID(i);
    option_widget(o, w.kind.c_str(), e);
    ImGui::PopID();
    w = last_item(o.name, w.kind.c_str(), g[0].c_str());
  }
  close_to(0);
}

// The frame graph, while its header is open: a window left of the panel
// with each pass as a box (its name, its time as a bar, its inputs on the
// left and outputs on the right as buttons that show the target in the
// inspector), a column for each depth (a pass stands right of every pass
// whose output it reads) and an edge from each output to each later pass
// that reads it; culled passes grey. Its bars change every frame, and so
// the panel's image: closed by default.
static bool graph_header(lm_panel *p, const panel_model *m) {
  if (!m->pass_count) return false;
  bool open = ImGui::CollapsingHeader("frame graph");
  p->controls.push_back(last_item("graph", "header", "panel"));
  if (open) ImGui::TextDisabled("left of the panel: a target's button inspects it");
  return open;
}

static void graph_window(lm_panel *p, const panel_model *m, panel_edits *e, float left_width, float height) {
  int n = m->pass_count, columns = 1;
  std::vector<int> column(n);
  for (int i = 0; i < n; i++) column[i] = m->passes[i].column, columns = std::max(columns, column[i] + 1);
  const ImGuiStyle &style = ImGui::GetStyle();
  float line = ImGui::GetTextLineHeightWithSpacing(), pad = style.FramePadding.x, gap = 36;
  // Each box's size, each column's width, and the boxes' places within their column.
  std::vector<ImVec2> size(n), at(n);
  std::vector<float> width(columns, 0), bottom(columns, 0);
  for (int i = 0; i < n; i++) {
    const panel_pass &pass = m->passes[i];
    float w = ImGui::CalcTextSize(pass.name).x;
    for (int k = 0; k < pass.input_count + pass.output_count; k++) {
      int t = k < pass.input_count ? pass.inputs[k] : pass.outputs[k - pass.input_count];
      if (t >= 0 && t < m->target_count) w = std::max(w, ImGui::CalcTextSize(m->targets[t]).x);
    }
    size[i] = ImVec2(w + 4 * pad, (2 + pass.input_count + pass.output_count) * line + 2 * pad);
    width[column[i]] = std::max(width[column[i]], size[i].x);
  }
  std::vector<float> x(columns, pad);
  for (int c = 1; c < columns; c++) x[c] = x[c - 1] + width[c - 1] + gap;
  for (int i = 0; i < n; i++) {
    at[i] = ImVec2(x[column[i]], bottom[column[i]] + pad);
    bottom[column[i]] = at[i].y + size[i].y + line;
  }
  float content_h = *std::max_element(bottom.begin(), bottom.end());
  ImGui::SetNextWindowPos(ImVec2(0, 0), ImGuiCond_Always);
  ImGui::SetNextWindowSize(ImVec2(left_width, height), ImGuiCond_Always);
  ImGui::SetNextWindowContentSize(ImVec2(x[columns - 1] + width[columns - 1] + pad, content_h));
  ImGui::SetNextWindowBgAlpha(0.8f);
  ImGui::Begin("frame graph", nullptr,
               ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                   ImGuiWindowFlags_HorizontalScrollbar);
  ImVec2 origin = ImGui::GetCursorScreenPos();
  ImDrawList *draw = ImGui::GetWindowDrawList();
  double longest = 0;
  for (int i = 0; i < n; i++) longest = std::fmax(longest, m->passes[i].ms);
  // A target's slot: its row's middle at the box's left (inputs) or right (outputs) edge.
  auto slot = [&](int i, int row, bool input) {
    return ImVec2(origin.x + at[i].x + (input ? 0 : size[i].x), origin.y + at[i].y + (2 + row + 0.5f) * line + pad);
  };
  // Edges first, under the boxes: from the pass that last wrote a target before each reader.
  for (int i = 0; i < n; i++) {
    const panel_pass &pass = m->passes[i];
    for (int k = 0; k < pass.input_count; k++) {
      int w = pass.writers[k];
      if (w < 0 || w >= n) continue;
      const panel_pass &from = m->passes[w];
      int row = 0; // the target's row among the writer's outputs
      while (row < from.output_count && from.outputs[row] != pass.inputs[k]) row++;
      ImVec2 a = slot(w, from.input_count + row, false), b = slot(i, k, true);
      float bend = std::fmax(gap, 0.4f * std::fabs(b.x - a.x));
      bool grey = pass.culled || from.culled;
      draw->AddBezierCubic(a, ImVec2(a.x + bend, a.y), ImVec2(b.x - bend, b.y), b,
                           ImGui::GetColorU32(grey ? ImGuiCol_TextDisabled : ImGuiCol_PlotLines), 1.5f);
    }
  }
  ImVec2 clip_lo = ImGui::GetWindowPos(), clip_hi = ImVec2(clip_lo.x + left_width, clip_lo.y + height);
  for (int i = 0; i < n; i++) {
    const panel_pass &pass = m->passes[i];
    ImVec2 lo(origin.x + at[i].x, origin.y + at[i].y), hi(lo.x + size[i].x, lo.y + size[i].y);
    ImGui::PushID(i);
    if (pass.culled) ImGui::PushStyleVar(ImGuiStyleVar_Alpha, 0.45f);
    draw->AddRectFilled(lo, hi, ImGui::GetColorU32(ImGuiCol_FrameBg), 4);
    draw->AddRect(lo, hi, ImGui::GetColorU32(pass.culled ? ImGuiCol_TextDisabled : ImGuiCol_Border), 4);
    ImGui::SetCursorScreenPos(ImVec2(lo.x + pad, lo.y + pad));
    if (pass.culled) ImGui::TextDisabled("%s", pass.name);
    else ImGui::TextUnformatted(pass.name);
    // The time bar: its share of the longest pass's, the milliseconds on it.
    ImVec2 bar(lo.x + pad, lo.y + pad + line), bar_hi(hi.x - pad, bar.y + line - style.ItemSpacing.y);
    float share = longest > 0 && pass.ms > 0 ? static_cast<float>(pass.ms / longest) : 0.0f;
    draw->AddRectFilled(bar, ImVec2(bar.x + share * (bar_hi.x - bar.x), bar_hi.y),
                        ImGui::GetColorU32(ImGuiCol_PlotHistogram));
    char ms[32];
    if (pass.culled) snprintf(ms, sizeof ms, "culled");
    else snprintf(ms, sizeof ms, "%.2f ms", pass.ms);
    draw->AddText(ImVec2(bar.x + 2, bar.y), ImGui::GetColorU32(ImGuiCol_Text), ms);
    for (int k = 0; k < pass.input_count + pass.output_count; k++) {
      bool input = k < pass.input_count;
      int t = input ? pass.inputs[k] : pass.outputs[k - pass.input_count];
      if (t < 0 || t >= m->target_count) continue;
      float label = ImGui::CalcTextSize(m->targets[t]).x + 2 * pad;
      ImVec2 s = slot(i, k, input);
      ImGui::SetCursorScreenPos(ImVec2(input ? lo.x + pad : hi.x - pad - label, s.y - 0.5f * line));
      ImGui::PushID(k);
      if (ImGui::SmallButton(m->targets[t])) e->inspect = t;
      widget w = last_item(m->targets[t], "target", pass.name);
      ImVec2 a = ImGui::GetItemRectMin(), b = ImGui::GetItemRectMax();
      if (a.x < clip_lo.x || a.y < clip_lo.y || b.x > clip_hi.x || b.y > clip_hi.y) w.rect[0] = w.rect[1] = w.rect[2] = w.rect[3] = 0;
      p->controls.push_back(w);
      ImGui::PopID();
    }
    if (pass.culled) ImGui::PopStyleVar();
    ImGui::PopID();
  }
  ImGui::SetCursorScreenPos(ImVec2(origin.x, origin.y + content_h));
  ImGui::End();
}

// A/B: the wipe's other side rendered live, its technique and the one
// option it sets apart (with this option's widget, showing that side's value).
static void compare_section(lm_panel *p, const panel_model *m, panel_edits *e) {
  bool open = ImGui::CollapsingHeader("A/B");
  p->controls.push_back(last_item("ab", "header", "panel"));
  if (!open) return;
  bool on = m->compare_on;
  if (m->compare_technique >= 0 && ImGui::Checkbox("wipe (B)", &on)) e->compare_toggle = true;
  ImGui::TextDisabled("right of the line:");
  if (ImGui::BeginListBox("##B technique", ImVec2(-FLT_MIN, 4.5f * ImGui::GetTextLineHeightWithSpacing()))) {
    for (int i = 0; i < m->technique_count; i++) {
      if (ImGui::Selectable(m->techniques[i], i == m->compare_technique)) e->compare_technique = i;
      p->controls.push_back(last_item((std::string("ab=") + m->techniques[i]).c_str(), "list", "A/B"));
    }
    ImGui::EndListBox();
  }
  if (m->compare_technique < 0) return;
  if (ImGui::BeginCombo("B differs in", m->compare_option ? m->compare_option->name : "nothing")) {
    for (int i = 0; i < m->option_count; i++)
      if (m->options[i].type != LM_OPTION_OTHER &&
          ImGui::Selectable(m->options[i].name, m->compare_option && !strcmp(m->options[i].name, m->compare_option->name)))
        e->compare_pick = i;
    ImGui::EndCombo();
  }
  p->controls.push_back(last_item("ab-option", "combo", "A/B"));
  if (!m->compare_option) return;
  panel_edits b{};
  ImGui::PushID("B side");
  option_widget(*m->compare_option, widget_kind(*m->compare_option), &b);
  ImGui::PopID();
  p->controls.push_back(last_item("ab-value", widget_kind(*m->compare_option), "A/B"));
  if (b.option) {
    e->compare_set = true;
    snprintf(e->compare_name, sizeof e->compare_name, "%s", b.option_name);
    snprintf(e->compare_value, sizeof e->compare_value, "%s", b.option_value);
  }
}

// The error against the reference at a job's view: its figures and the
// error view's choice (view.h's ERROR_VIEW_* order).
static void reference_section(lm_panel *p, const panel_model *m, panel_edits *e) {
  if (!m->reference || !ImGui::CollapsingHeader("reference", ImGuiTreeNodeFlags_DefaultOpen)) return;
  ImGui::TextWrapped("%s", m->reference);
  if (!m->reference_here) return;
  static const char *const views[] = {"off", "wipe: reference", "wipe: error heat map"};
  int view = m->error_view;
  if (ImGui::Combo("error view (E)", &view, views, 3)) e->error_view = view;
  p->controls.push_back(last_item("error", "combo", "reference"));
}

// What the draw lists draw: vertices, indices, commands and the display size.
static uint64_t draw_hash(const ImDrawData *d) {
  uint64_t h = lm_hash(&d->DisplaySize, sizeof d->DisplaySize, 14695981039346656037ull);
  for (int i = 0; i < d->CmdListsCount; i++) {
    const ImDrawList *l = d->CmdLists[i];
    h = lm_hash(l->VtxBuffer.Data, sizeof(ImDrawVert) * static_cast<size_t>(l->VtxBuffer.Size), h);
    h = lm_hash(l->IdxBuffer.Data, sizeof(ImDrawIdx) * static_cast<size_t>(l->IdxBuffer.Size), h);
    for (const ImDrawCmd &c : l->CmdBuffer) {
      h = lm_hash(&c.ClipRect, sizeof c.ClipRect, h);
      h = lm_hash(&c.TextureId, sizeof c.TextureId, h);
      unsigned counts[3] = {c.ElemCount, c.IdxOffset, c.VtxOffset};
      h = lm_hash(counts, sizeof counts, h);
    }
  }
  return h;
}

// A string in a hash, NULL apart from "".
static uint64_t hash_text(const char *s, uint64_t h) { return s ? lm_hash(s, strlen(s) + 1, h) : lm_hash("\1", 1, h); }

template <typename T> static uint64_t hash_value(const T &x, uint64_t h) { return lm_hash(&x, sizeof x, h); }

// What the model shows at this size. The frame graph's times change every
// frame: they count only while its window is open.
static uint64_t model_hash(const panel_model *m, int width, int height, bool graph_open) {
  uint64_t h = hash_value(width, hash_value(height, 14695981039346656037ull));
  for (int i = 0; i < m->option_count; i++) {
    const lm_option_info &o = m->options[i];
    h = hash_text(o.value, hash_text(o.name, h));
    h = hash_value(o.lo, hash_value(o.hi, hash_value(o.step, hash_value(o.rule, hash_value(o.type, h)))));
  }
  for (int i = 0; i < m->technique_count; i++) h = hash_text(m->techniques[i], h);
  if (m->animated) // a still scene's time runs on unseen
    h = hash_value(m->time, hash_value(m->time_lo, hash_value(m->time_hi, hash_value(m->paused, h))));
  h = hash_value(m->technique, hash_value(m->compare_technique, hash_value(m->compare_on, h)));
  h = hash_value(m->reference_here, hash_value(m->error_view, h));
  h = hash_text(m->status, hash_text(m->cost, hash_text(m->reference, h)));
  if (m->compare_option) h = hash_text(m->compare_option->value, hash_text(m->compare_option->name, h));
  for (int i = 0; graph_open && i < m->pass_count; i++) {
    const panel_pass &pass = m->passes[i];
    h = hash_value(pass.ms, hash_value(pass.culled, hash_text(pass.name, h)));
    h = lm_hash(pass.inputs, sizeof *pass.inputs * static_cast<size_t>(pass.input_count), h);
    h = lm_hash(pass.outputs, sizeof *pass.outputs * static_cast<size_t>(pass.output_count), h);
  }
  for (int i = 0; graph_open && i < m->target_count; i++) h = hash_text(m->targets[i], h);
  return h;
}

// The input ImGui sees this frame: the mouse, keys, typed text and the wheel.
static uint64_t input_hash(const ImGuiIO &io) {
  uint64_t h = hash_value(io.MousePos, hash_value(io.MouseDown, 14695981039346656037ull));
  h = hash_value(io.KeysDown, hash_value(io.KeyCtrl, hash_value(io.KeyShift, hash_value(io.KeyAlt, h))));
  return hash_value(io.MouseWheel, hash_value(io.MouseWheelH, hash_value(io.InputQueueCharacters.Size, h)));
}

// The rectangle the draw lists' vertices cover, in window pixels from the
// bottom left (x, y, width, height): all the panel draws.
static void cover(const ImDrawData *d, int width, int height, int rect[4]) {
  float lo[2] = {FLT_MAX, FLT_MAX}, hi[2] = {-FLT_MAX, -FLT_MAX};
  for (int i = 0; i < d->CmdListsCount; i++)
    for (const ImDrawVert &v : d->CmdLists[i]->VtxBuffer) {
      lo[0] = std::fmin(lo[0], v.pos.x), lo[1] = std::fmin(lo[1], v.pos.y);
      hi[0] = std::fmax(hi[0], v.pos.x), hi[1] = std::fmax(hi[1], v.pos.y);
    }
  float w = static_cast<float>(width), h = static_cast<float>(height);
  int x0 = static_cast<int>(std::floor(std::fmin(std::fmax(lo[0], 0.0f), w)));
  int y0 = static_cast<int>(std::floor(std::fmin(std::fmax(lo[1], 0.0f), h)));
  int x1 = static_cast<int>(std::ceil(std::fmin(std::fmax(hi[0], 0.0f), w)));
  int y1 = static_cast<int>(std::ceil(std::fmin(std::fmax(hi[1], 0.0f), h)));
  rect[0] = x0, rect[1] = height - y1, rect[2] = std::max(0, x1 - x0), rect[3] = std::max(0, y1 - y0);
}

panel_image panel_frame(lm_panel *p, const panel_model *m, int width, int height, panel_edits *e) {
  *e = panel_edits{};
  e->technique = -1, e->inspect = -1, e->error_view = -1, e->compare_technique = -1, e->compare_pick = -1;
  ImGuiIO &io = ImGui::GetIO();
  if (p->scripted) {
    io.MousePos = ImVec2(static_cast<float>(p->mouse[0]), static_cast<float>(p->mouse[1]));
    io.MouseDown[0] = p->mouse_down;
  } else {
    io.MousePos = ImVec2(static_cast<float>(cursor[0]), static_cast<float>(cursor[1]));
    for (int i = 0; i < ImGuiMouseButton_COUNT; i++) {
      io.MouseDown[i] = pressed[i] || glfwGetMouseButton(p->window, i) == GLFW_PRESS;
      pressed[i] = false;
    }
  }
  // Unchanged for a few frames (a click, a hover settle over two or three)
  // and nothing held or typed into: the last frame's panel stands.
  enum { SETTLE_FRAMES = 3 };
  uint64_t input = input_hash(io), model = model_hash(m, width, height, p->graph_open);
  p->quiet = input == p->input && model == p->model && !ImGui::IsAnyItemActive() ? p->quiet + 1 : 0;
  p->input = input, p->model = model;
  if (p->quiet > SETTLE_FRAMES && p->shown.texture.id && p->image_w == width && p->image_h == height) return p->shown;
  ImGui_ImplOpenGL3_NewFrame();
  double now = lm_now_ms();
  io.DisplaySize = ImVec2(static_cast<float>(width), static_cast<float>(height));
  io.DeltaTime = p->last_ms > 0 ? static_cast<float>(std::fmax((now - p->last_ms) * 1e-3, 1e-4)) : 1.0f / 60.0f;
  p->last_ms = now;
  ImGui::NewFrame();
  float w = std::floor(std::fmin(320.0f, 0.45f * static_cast<float>(width))); // whole pixels: opaque to its edge
  ImGui::SetNextWindowPos(ImVec2(static_cast<float>(width) - w, 0), ImGuiCond_Always);
  ImGui::SetNextWindowSize(ImVec2(w, static_cast<float>(height)), ImGuiCond_Always);
  ImGui::Begin("limn", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
  ImGui::PushItemWidth(-ImGui::GetWindowWidth() * 0.45f);
  p->controls.clear();
  if (ImGui::Button("Write job (J)")) e->write_job = true;
  p->controls.push_back(last_item("job", "button", "panel"));
  if (m->status) ImGui::TextWrapped("%s", m->status);
  if (m->cost) ImGui::TextDisabled("%s", m->cost);
  if (m->animated && ImGui::CollapsingHeader("time", ImGuiTreeNodeFlags_DefaultOpen)) {
    if (ImGui::Button(m->paused ? "Play (Space)" : "Pause (Space)")) e->play = true;
    p->controls.push_back(last_item("play", "button", "time"));
    /* The knob within the keys (a time of 1e300 is past a float's range); the text says the time itself. */
    float lo = static_cast<float>(m->time_lo), hi = static_cast<float>(std::fmax(m->time_hi, m->time_lo + 1e-3));
    float t = static_cast<float>(std::fmin(std::fmax(m->time, lo), hi));
    std::string shown = std::string(m->time_text) + " s";
    if (ImGui::SliderFloat("time##scrub", &t, lo, hi, shown.c_str())) e->scrub = true, e->scrub_time = t;
    p->controls.push_back(last_item("time", "slider", "time"));
  }
  p->techniques.assign(m->technique_count, widget{});
  if (ImGui::CollapsingHeader("techniques", ImGuiTreeNodeFlags_DefaultOpen) &&
      ImGui::BeginListBox("##techniques", ImVec2(-FLT_MIN, 5.5f * ImGui::GetTextLineHeightWithSpacing()))) {
    for (int i = 0; i < m->technique_count; i++) {
      if (ImGui::Selectable(m->techniques[i], i == m->technique)) e->technique = i;
      if (i == m->technique && ImGui::IsWindowAppearing()) ImGui::SetScrollHereY();
      p->techniques[i] = last_item(m->techniques[i], "technique", "techniques");
    }
    ImGui::EndListBox();
  }
  compare_section(p, m, e);
  reference_section(p, m, e);
  bool graph = graph_header(p, m);
  options_section(p, m, e);
  ImGui::PopItemWidth();
  ImGui::End();
  if (graph) graph_window(p, m, e, static_cast<float>(width) - w, static_cast<float>(height));
  p->graph_open = graph;
  ImGui::Render();
  ImDrawData *d = ImGui::GetDrawData();
  p->shown = panel_image{};
  if (!p->image.id || p->image_w != width || p->image_h != height) {
    lm_texture_destroy(&p->image);
    lm_texture_desc desc = {LM_FORMAT_RGBA8, width, height, false};
    lm_error err;
    if (!lm_texture_create(&p->image, &desc, "viewer panel", &err)) return p->shown;
    p->image_w = width, p->image_h = height, p->drawn = 0;
  }
  uint64_t h = draw_hash(d);
  if (h != p->drawn) { // premultiplied: ImGui blends alpha as "over" into the cleared image
    lm_attachments att = {{p->image}, 1, {0}, width, height};
    lm_error err;
    if (!lm_attachments_bind(&att, &err)) return p->shown;
    lm_texture_clear(p->image);
    ImGui_ImplOpenGL3_RenderDrawData(d);
    p->drawn = h;
  }
  p->shown.texture = p->image;
  cover(d, width, height, p->shown.cover);
  p->shown.column = width - static_cast<int>(w);
  return p->shown;
}

void panel_list_widgets(const lm_panel *p, FILE *out) {
  for (const widget &w : p->widgets)
    fprintf(out, "panel widget %s %s %s %.0f %.0f %.0f %.0f\n", w.name.c_str(), w.kind.c_str(), w.group.c_str(),
            w.rect[0], w.rect[1], w.rect[2], w.rect[3]);
  for (const std::vector<widget> *list : {&p->techniques, &p->controls})
    for (const widget &w : *list)
      fprintf(out, "panel %s %s %.0f %.0f %.0f %.0f\n",
              w.kind == "technique" || w.kind == "target" ? w.kind.c_str() : "control", w.name.c_str(), w.rect[0],
              w.rect[1], w.rect[2], w.rect[3]);
  fflush(out);
}
