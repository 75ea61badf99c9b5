/* FreeType text for the viewer's overlay. Monospaced ASCII is all the
 * overlay needs, so the 95 printable glyphs are rendered once at open. */
#include "view_text.h"

#include <ft2build.h>
#include FT_FREETYPE_H
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define DEFAULT_FONT "/usr/share/fonts/truetype/dejavu/DejaVuSansMono.ttf"

typedef struct glyph {
  int w, h, left, top; /* bitmap size and bearing from the pen on the baseline */
  uint8_t *alpha;
} glyph;

struct lm_font {
  glyph glyphs[128];
  int ascent, line, advance;
};

lm_font *lm_font_open(int pixels, lm_error *err) {
  const char *path = getenv("LIMN_FONT");
  if (!path || !*path) path = DEFAULT_FONT;
  FT_Library lib;
  if (FT_Init_FreeType(&lib)) {
    lm_error_set(err, "FreeType would not start");
    return NULL;
  }
  FT_Face face;
  if (FT_New_Face(lib, path, 0, &face)) {
    lm_error_set(err, "%s: cannot load the font (install fonts-dejavu-core, or set LIMN_FONT)", path);
    FT_Done_FreeType(lib);
    return NULL;
  }
  FT_Set_Pixel_Sizes(face, 0, (FT_UInt)pixels);
  lm_font *f = lm_alloc(sizeof *f);
  f->ascent = (int)(face->size->metrics.ascender >> 6);
  f->line = (int)(face->size->metrics.height >> 6);
  for (int c = 32; c < 127; c++) {
    if (FT_Load_Char(face, (FT_ULong)c, FT_LOAD_RENDER)) continue;
    FT_GlyphSlot s = face->glyph;
    glyph *g = &f->glyphs[c];
    g->w = (int)s->bitmap.width, g->h = (int)s->bitmap.rows;
    g->left = s->bitmap_left, g->top = s->bitmap_top;
    g->alpha = lm_alloc((size_t)g->w * (size_t)g->h + 1);
    for (int y = 0; y < g->h; y++)
      memcpy(g->alpha + (size_t)y * g->w, s->bitmap.buffer + (ptrdiff_t)y * s->bitmap.pitch, (size_t)g->w);
    if (c == 'M') f->advance = (int)(s->advance.x >> 6);
  }
  if (f->advance < 1) f->advance = pixels / 2 + 1;
  FT_Done_Face(face);
  FT_Done_FreeType(lib);
  return f;
}

void lm_font_close(lm_font *f) {
  if (!f) return;
  for (int c = 0; c < 128; c++) free(f->glyphs[c].alpha);
  free(f);
}

int lm_font_line_height(const lm_font *f) { return f->line; }
int lm_font_advance(const lm_font *f) { return f->advance; }

/* Premultiplied "over": src colour c with coverage a (0..255). */
static void blend(uint8_t *px, const uint8_t c[3], int a) {
  for (int i = 0; i < 3; i++) px[i] = (uint8_t)((c[i] * a + px[i] * (255 - a)) / 255);
  px[3] = (uint8_t)(a + px[3] * (255 - a) / 255);
}

void lm_font_draw(const lm_font *f, uint8_t *rgba, int w, int h, int x, int y, const char *text,
                  const uint8_t color[3]) {
  static const uint8_t black[3] = {0, 0, 0};
  int n = (int)strlen(text);
  for (int py = y; py < y + f->line && py < h; py++) /* the band behind the line */
    for (int px = x - 2; px < x + n * f->advance + 2 && px < w; px++)
      if (py >= 0 && px >= 0) blend(rgba + ((size_t)py * w + px) * 4, black, 150);
  int pen = x, base = y + f->ascent;
  for (const char *c = text; *c; c++, pen += f->advance) {
    unsigned char ch = (unsigned char)*c;
    const glyph *g = ch < 128 ? &f->glyphs[ch] : &f->glyphs['?'];
    for (int gy = 0; gy < g->h; gy++) {
      int py = base - g->top + gy;
      if (py < 0 || py >= h) continue;
      for (int gx = 0; gx < g->w; gx++) {
        int px = pen + g->left + gx;
        if (px < 0 || px >= w) continue;
        int a = g->alpha[(size_t)gy * g->w + gx];
        if (a) blend(rgba + ((size_t)py * w + px) * 4, color, a);
      }
    }
  }
}
