/* Text for the viewer's overlay: glyphs rendered once by FreeType into a
 * CPU glyph cache, then drawn into an RGBA image the viewer uploads. */
#ifndef LIMN_VIEW_TEXT_H
#define LIMN_VIEW_TEXT_H

#include <stdint.h>

#include "core/core.h"

typedef struct lm_font lm_font;

/* DejaVu Sans Mono (fonts-dejavu-core) at `pixels` high; $LIMN_FONT names another file. */
lm_font *lm_font_open(int pixels, lm_error *err);
void lm_font_close(lm_font *f);
int lm_font_line_height(const lm_font *f);
int lm_font_advance(const lm_font *f); /* a monospaced cell's width */
/* Draws one line of ASCII text with its top-left at (x, y) into a premultiplied
 * RGBA image of w x h (top row first), over a translucent dark band. */
void lm_font_draw(const lm_font *f, uint8_t *rgba, int w, int h, int x, int y, const char *text,
                  const uint8_t color[3]);

#endif
