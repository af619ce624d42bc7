/*
** effects.c — parse and print the `effects KEY=VALUE ...` line (shared/CONTRACT.md,
** "Effects"; papers 000-004 for the effects themselves).
**
** This file contains code to turn the effects text of a scene (or of `--effects`) into a
** struct effects. The text is a list of blank-separated tokens KEY or KEY=VALUE. Each key
** may be named once; a key named without a value takes the contract's default (the value
** the contract lists first). Values are checked completely: numbers must be whole tokens
** (no trailing junk) inside their documented ranges, names must be one of the listed
** words. Everything else is an input error reported at the effects line, so a typo never
** silently disables an effect. effects_format prints the keys given in one canonical
** order with full values, for --stats and for tests.
*/
#include "render/effects.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SHOW_MAX 40     /* at most this many bytes of a bad token are echoed */

void effects_default(struct effects *out)
{
  memset(out, 0, sizeof *out);
  out->halftone = 4;
  out->pattern[0] = '\0';
  out->aa = EFFECTS_AA_NONE;
  out->filter = EFFECTS_FILTER_BOX;
  out->n = 3;
  out->super = 3;
  out->sigma = 0.5;
  out->depth = 3;
  out->edges = false;
  out->shadows = false;
  out->outline_w = 1.5;
  out->outline_g = 0;
  out->inner_w = 0.75;
  out->inner_g = 160;
  out->halo_w = 0.75;
  out->halo_g = 255;
  out->smooth = EFFECTS_SMOOTH_NONE;
  out->smooth_c = 0.0;
  out->contour_on = false;
  out->contour = 0.0;
  out->tube = EFFECTS_TUBE_STORED;
  out->fade_seconds = 0.0;
}

/* Copy s[0..len) into buf for a message: non-printable bytes become '?', long text is
   cut with "...". buf must hold SHOW_MAX + 4 bytes. */
static const char *show(const char *s, size_t len, char *buf)
{
  size_t k = 0;
  for (; k < len && k < SHOW_MAX; k++) {
    unsigned char c = (unsigned char)s[k];
    buf[k] = (c >= 0x20 && c < 0x7f) ? (char)c : '?';
  }
  if (k < len) { memcpy(buf + k, "...", 3); k += 3; }
  buf[k] = '\0';
  return buf;
}

/* A decimal integer filling the whole of s[0..len) (optional sign), in lo..hi. */
static bool int_value(const char *s, size_t len, long lo, long hi, long *out)
{
  size_t i = 0;
  bool neg = false;
  if (i < len && (s[i] == '+' || s[i] == '-')) { neg = s[i] == '-'; i++; }
  if (i == len) return false;
  long v = 0;
  for (; i < len; i++) {
    if (s[i] < '0' || s[i] > '9') return false;
    v = v * 10 + (s[i] - '0');
    if (v > 100000000L) return false;   /* far beyond every range here: no overflow */
  }
  if (neg) v = -v;
  if (v < lo || v > hi) return false;
  *out = v;
  return true;
}

/* A finite decimal number filling the whole of s[0..len), in lo..hi. */
static bool real_value(const char *s, size_t len, double lo, double hi, double *out)
{
  char tmp[64];
  if (len == 0 || len >= sizeof tmp) return false;
  memcpy(tmp, s, len);
  tmp[len] = '\0';
  /* strtod also takes hex, "inf" and "nan": only plain decimals are wanted */
  for (size_t i = 0; i < len; i++)
    if (!isdigit((unsigned char)tmp[i]) && !strchr("+-.eE", tmp[i])) return false;
  char *end;
  errno = 0;
  double v = strtod(tmp, &end);
  if (end != tmp + len || errno == ERANGE || !isfinite(v) || v < lo || v > hi) return false;
  *out = v;
  return true;
}

static bool is_word(const char *s, size_t len)
{
  if (len == 0 || len > EFFECTS_PATTERN_MAX) return false;
  for (size_t i = 0; i < len; i++)
    if (!isalnum((unsigned char)s[i]) && s[i] != '_' && s[i] != '-') return false;
  return true;
}

static bool eq(const char *s, size_t len, const char *word)
{
  return strlen(word) == len && memcmp(s, word, len) == 0;
}

/* "W,G": width 0..EFFECTS_WIDTH_MAX points (a decimal, fractions allowed), grey 0..255. */
static bool width_grey(const char *s, size_t len, double *w, int *g)
{
  const char *comma = memchr(s, ',', len);
  if (!comma) return false;
  long lg;
  double dw;
  size_t n1 = (size_t)(comma - s);
  if (!real_value(s, n1, 0.0, EFFECTS_WIDTH_MAX, &dw)) return false;
  if (!int_value(comma + 1, len - n1 - 1, 0, 255, &lg)) return false;
  *w = dw;
  *g = (int)lg;
  return true;
}

/* Report a problem: "FILE:LINE: effects: ..." or "effects: ..." without a file. */
static int fail(struct t74_error *err, const char *file, int line, const char *what,
                const char *tok, size_t len)
{
  char buf[SHOW_MAX + 4];
  show(tok, len, buf);
  if (file) return t74_fail_at(err, T74_EINPUT, file, line, "effects: %s `%s`", what, buf);
  return t74_fail(err, T74_EINPUT, "effects: %s `%s`", what, buf);
}

/* Apply one KEY[=VALUE] token. key/klen is the key; val is NULL when no '=' was given. */
static int apply(struct effects *e, const char *key, size_t klen, const char *val,
                 size_t vlen, const char *tok, size_t toklen, const char *file, int line,
                 struct t74_error *err)
{
  long l;
  double d;
  unsigned bit;
  bool ok = true;

  if (val && vlen == 0)
    return fail(err, file, line, "empty value in", tok, toklen);

  if (eq(key, klen, "halftone")) {
    bit = EFFECTS_HALFTONE;
    if (!val || eq(val, vlen, "4x4") || eq(val, vlen, "4")) e->halftone = 4;
    else if (eq(val, vlen, "3x3") || eq(val, vlen, "3")) e->halftone = 3;
    else ok = false;
  } else if (eq(key, klen, "pattern")) {
    bit = EFFECTS_PATTERN;
    if (!val) return fail(err, file, line, "pattern needs a name:", tok, toklen);
    if (is_word(val, vlen)) { memcpy(e->pattern, val, vlen); e->pattern[vlen] = '\0'; }
    else ok = false;
  } else if (eq(key, klen, "aa")) {
    bit = EFFECTS_AA;
    if (!val || eq(val, vlen, "none")) e->aa = EFFECTS_AA_NONE;
    else if (eq(val, vlen, "multiscan")) e->aa = EFFECTS_AA_MULTISCAN;
    else if (eq(val, vlen, "area")) e->aa = EFFECTS_AA_AREA;
    else if (eq(val, vlen, "super")) e->aa = EFFECTS_AA_SUPER;
    else if (eq(val, vlen, "exact")) e->aa = EFFECTS_AA_EXACT;
    else ok = false;
  } else if (eq(key, klen, "filter")) {
    bit = EFFECTS_FILTER;
    if (!val || eq(val, vlen, "box")) e->filter = EFFECTS_FILTER_BOX;
    else if (eq(val, vlen, "gauss")) e->filter = EFFECTS_FILTER_GAUSS;
    else ok = false;
  } else if (eq(key, klen, "n")) {
    bit = EFFECTS_N;
    if (!val) e->n = 3;
    else if (int_value(val, vlen, 1, EFFECTS_NSUB_MAX, &l)) e->n = (int)l;
    else ok = false;
  } else if (eq(key, klen, "super")) {
    bit = EFFECTS_SUPER;
    if (!val) e->super = 3;
    else if (int_value(val, vlen, 1, EFFECTS_NSUB_MAX, &l)) e->super = (int)l;
    else ok = false;
  } else if (eq(key, klen, "sigma")) {
    bit = EFFECTS_SIGMA;
    if (!val) return fail(err, file, line, "sigma needs a value:", tok, toklen);
    if (real_value(val, vlen, 0.0, EFFECTS_SIGMA_MAX, &d) && d > 0.0) e->sigma = d;
    else ok = false;
  } else if (eq(key, klen, "depth")) {
    bit = EFFECTS_DEPTH;
    if (!val) e->depth = 3;
    else if (int_value(val, vlen, 1, EFFECTS_DEPTH_MAX, &l)) e->depth = (int)l;
    else ok = false;
  } else if (eq(key, klen, "shadows")) {
    bit = EFFECTS_SHADOWS;
    if (!val || eq(val, vlen, "on")) e->shadows = true;
    else if (eq(val, vlen, "off")) e->shadows = false;
    else ok = false;
  } else if (eq(key, klen, "edges")) {
    bit = EFFECTS_EDGES;
    if (!val || eq(val, vlen, "on")) e->edges = true;
    else if (eq(val, vlen, "off")) e->edges = false;
    else ok = false;
  } else if (eq(key, klen, "outline")) {
    bit = EFFECTS_OUTLINE;
    if (!val) return fail(err, file, line, "outline needs W,G:", tok, toklen);
    ok = width_grey(val, vlen, &e->outline_w, &e->outline_g);
  } else if (eq(key, klen, "inner")) {
    bit = EFFECTS_INNER;
    if (!val) return fail(err, file, line, "inner needs W,G:", tok, toklen);
    ok = width_grey(val, vlen, &e->inner_w, &e->inner_g);
  } else if (eq(key, klen, "halo")) {
    bit = EFFECTS_HALO;
    if (!val) return fail(err, file, line, "halo needs W,G:", tok, toklen);
    ok = width_grey(val, vlen, &e->halo_w, &e->halo_g);
  } else if (eq(key, klen, "smooth")) {
    bit = EFFECTS_SMOOTH;
    if (!val || eq(val, vlen, "gouraud")) e->smooth = EFFECTS_SMOOTH_GOURAUD;
    else if (eq(val, vlen, "phong")) e->smooth = EFFECTS_SMOOTH_PHONG;
    else if (vlen > 6 && memcmp(val, "fixed:", 6) == 0 &&
             real_value(val + 6, vlen - 6, 0.0, 1e6, &d)) {
      e->smooth = EFFECTS_SMOOTH_FIXED;
      e->smooth_c = d;
    } else if (vlen > 5 && memcmp(val, "prop:", 5) == 0 &&
               real_value(val + 5, vlen - 5, 0.0, 1e6, &d)) {
      e->smooth = EFFECTS_SMOOTH_PROP;
      e->smooth_c = d;
    } else ok = false;
  } else if (eq(key, klen, "contour")) {
    bit = EFFECTS_CONTOUR;
    if (!val) return fail(err, file, line, "contour needs a value:", tok, toklen);
    if (eq(val, vlen, "none")) { e->contour_on = false; e->contour = 0.0; }
    else if (real_value(val, vlen, 0.0, 1.0, &d)) { e->contour_on = true; e->contour = d; }
    else ok = false;
  } else if (eq(key, klen, "tube")) {
    bit = EFFECTS_TUBE;
    if (!val || eq(val, vlen, "stored")) e->tube = EFFECTS_TUBE_STORED;
    else if (eq(val, vlen, "flash")) e->tube = EFFECTS_TUBE_FLASH;
    else if (vlen > 5 && memcmp(val, "fade:", 5) == 0 &&
             real_value(val + 5, vlen - 5, EFFECTS_FADE_MIN, EFFECTS_FADE_MAX, &d)) {
      e->tube = EFFECTS_TUBE_FADE;
      e->fade_seconds = d;
    } else ok = false;
  } else {
    return fail(err, file, line, "unknown key", key, klen);
  }
  if (e->given & bit) return fail(err, file, line, "key given twice:", key, klen);
  if (!ok) return fail(err, file, line, "bad value in", tok, toklen);
  e->given |= bit;
  return T74_OK;
}

int effects_parse(const char *text, struct effects *out, const char *file, int line,
                  struct t74_error *err)
{
  effects_default(out);
  if (!text) return T74_OK;
  const char *p = text;
  for (;;) {
    while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n') p++;
    if (!*p) break;
    const char *tok = p;
    while (*p && *p != ' ' && *p != '\t' && *p != '\r' && *p != '\n') p++;
    size_t toklen = (size_t)(p - tok);
    const char *eqs = memchr(tok, '=', toklen);
    size_t klen = eqs ? (size_t)(eqs - tok) : toklen;
    const char *val = eqs ? eqs + 1 : NULL;
    size_t vlen = eqs ? toklen - klen - 1 : 0;
    if (klen == 0) return fail(err, file, line, "missing key in", tok, toklen);
    int st = apply(out, tok, klen, val, vlen, tok, toklen, file, line, err);
    if (st != T74_OK) return st;
  }
  return T74_OK;
}

static const char *const aa_name[] = { "none", "multiscan", "area", "super", "exact" };
static const char *const filter_name[] = { "box", "gauss" };

/* Append to buf like snprintf; *len counts the full length even past n. */
static void put(char *buf, size_t n, size_t *len, const char *text)
{
  size_t t = strlen(text);
  if (*len > 0) {
    if (*len + 1 < n) buf[*len] = ' ';
    (*len)++;
  }
  for (size_t i = 0; i < t; i++, (*len)++)
    if (*len + 1 < n) buf[*len] = text[i];
  if (n > 0) buf[*len < n ? *len : n - 1] = '\0';
}

int effects_format(const struct effects *e, char *buf, size_t n)
{
  char t[96];
  size_t len = 0;
  if (n > 0) buf[0] = '\0';
  if (e->given & EFFECTS_HALFTONE)
    put(buf, n, &len, e->halftone == 3 ? "halftone=3x3" : "halftone=4x4");
  if (e->given & EFFECTS_PATTERN) {
    snprintf(t, sizeof t, "pattern=%s", e->pattern);
    put(buf, n, &len, t);
  }
  if (e->given & EFFECTS_AA) {
    snprintf(t, sizeof t, "aa=%s", aa_name[e->aa]);
    put(buf, n, &len, t);
  }
  if (e->given & EFFECTS_FILTER) {
    snprintf(t, sizeof t, "filter=%s", filter_name[e->filter]);
    put(buf, n, &len, t);
  }
  if (e->given & EFFECTS_N) { snprintf(t, sizeof t, "n=%d", e->n); put(buf, n, &len, t); }
  if (e->given & EFFECTS_SUPER) {
    snprintf(t, sizeof t, "super=%d", e->super);
    put(buf, n, &len, t);
  }
  if (e->given & EFFECTS_SIGMA) { snprintf(t, sizeof t, "sigma=%g", e->sigma); put(buf, n, &len, t); }
  if (e->given & EFFECTS_DEPTH) { snprintf(t, sizeof t, "depth=%d", e->depth); put(buf, n, &len, t); }
  if (e->given & EFFECTS_EDGES) put(buf, n, &len, e->edges ? "edges=on" : "edges=off");
  if (e->given & EFFECTS_SHADOWS) put(buf, n, &len, e->shadows ? "shadows=on" : "shadows=off");
  if (e->given & EFFECTS_OUTLINE) {
    snprintf(t, sizeof t, "outline=%g,%d", e->outline_w, e->outline_g);
    put(buf, n, &len, t);
  }
  if (e->given & EFFECTS_INNER) {
    snprintf(t, sizeof t, "inner=%g,%d", e->inner_w, e->inner_g);
    put(buf, n, &len, t);
  }
  if (e->given & EFFECTS_HALO) {
    snprintf(t, sizeof t, "halo=%g,%d", e->halo_w, e->halo_g);
    put(buf, n, &len, t);
  }
  if (e->given & EFFECTS_SMOOTH) {
    switch (e->smooth) {
    case EFFECTS_SMOOTH_PHONG: snprintf(t, sizeof t, "smooth=phong"); break;
    case EFFECTS_SMOOTH_FIXED: snprintf(t, sizeof t, "smooth=fixed:%g", e->smooth_c); break;
    case EFFECTS_SMOOTH_PROP:  snprintf(t, sizeof t, "smooth=prop:%g", e->smooth_c); break;
    default:                   snprintf(t, sizeof t, "smooth=gouraud"); break;
    }
    put(buf, n, &len, t);
  }
  if (e->given & EFFECTS_CONTOUR) {
    if (e->contour_on) snprintf(t, sizeof t, "contour=%g", e->contour);
    else snprintf(t, sizeof t, "contour=none");
    put(buf, n, &len, t);
  }
  if (e->given & EFFECTS_TUBE) {
    if (e->tube == EFFECTS_TUBE_FADE) snprintf(t, sizeof t, "tube=fade:%g", e->fade_seconds);
    else snprintf(t, sizeof t, "tube=%s", e->tube == EFFECTS_TUBE_FLASH ? "flash" : "stored");
    put(buf, n, &len, t);
  }
  return len > (size_t)2147483647 ? 2147483647 : (int)len;
}
