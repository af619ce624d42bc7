/*
** test_look.c — tests of the tube's timing and look (display/beam.h, display/look.h).
** Sources: paper 003 appendix (21 x 16.3 cm face, 400 x 300 points, erase under 500 ms);
** docs/hardware.md (Tektronix 613 settling: 14 us + 6 us/cm up to 2 cm, 3 us/cm beyond;
** rricharz/Tek4010 look constants).
**
** This file contains code to check, against the numbers in the parameter tables and
** hand computations:
**   beam   settling of short and long moves against the 613 formula; the distance on the
**          face from the dot pitch; dot times (max of computing time and the beam's last
**          dot, plus move and dwell) and tube_seconds / total_1974_seconds on a tiny
**          sequence computed by hand; the parameter table.
**   look   one stored dot's spot: its profile (pixel means of the Gaussian, symmetric,
**          peak at the dot) and its energy (sum over the spot = peak * 2 pi sigma^2) at
**          every scale; the flood glow; the bright flash's linear decay; write-through
**          traces fading and never stored; erase timing (under 500 ms: the flash, then a
**          cleared face); fading only when asked, and then with its energy law; colours;
**          the PNG writer.
** A standalone cmocka program.
*/
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "display/beam.h"
#include "display/look.h"
#include "display/sink.h"
#include "emu/status.h"

#define PI 3.14159265358979323846

/* ---- beam -------------------------------------------------------------------------- */

static void test_settle_613(void **state)
{
  (void)state;
  struct beam_params p;
  beam_params_default(&p);
  assert_true(beam_settle_us(&p, 0) == 0);                      /* no move, no settle */
  assert_true(fabs(beam_settle_us(&p, 0.5) - (14 + 6 * 0.5)) < 1e-9);
  assert_true(fabs(beam_settle_us(&p, 1.0) - 20) < 1e-9);
  assert_true(fabs(beam_settle_us(&p, 2.0) - 26) < 1e-9);      /* 14 + 6 * 2 */
  assert_true(fabs(beam_settle_us(&p, 5.0) - (26 + 3 * 3)) < 1e-9);
  assert_true(fabs(beam_settle_us(&p, 21.0) - (26 + 3 * 19)) < 1e-9);
  /* continuous and growing: just past 2 cm is just past 26 us */
  assert_true(beam_settle_us(&p, 2.001) > 26 && beam_settle_us(&p, 2.001) < 26.01);
  /* one dot across is 21/400 cm, one dot up 16.3/300 cm */
  assert_true(fabs(beam_distance_cm(&p, 0, 0, 1, 0) - 0.0525) < 1e-12);
  assert_true(fabs(beam_distance_cm(&p, 0, 0, 0, 1) - 16.3 / 300) < 1e-12);
  assert_true(fabs(beam_distance_cm(&p, 0, 0, 400, 300) - sqrt(21.0 * 21.0 + 16.3 * 16.3)) < 1e-9);
}

static void test_beam_sequence(void **state)
{
  (void)state;
  struct beam_params p;
  beam_params_default(&p);                     /* dwell 10 us, home (0, 0) */
  struct beam b;
  beam_init(&b, &p);
  /* (0,0) at computing time 0: no move, 10 us dwell -> written at 10 us */
  double t1 = beam_dot(&b, 0, 0, 0);
  assert_true(fabs(t1 - 10e-6) < 1e-12);
  /* (10,0) also computed at 0, but the beam is busy until 10 us: 0.525 cm move,
     settle 14 + 6 * 0.525 = 17.15 us, dwell 10 -> 37.15 us */
  double t2 = beam_dot(&b, 10, 0, 0);
  assert_true(fabs(t2 - 37.15e-6) < 1e-12);
  /* (10,299) computed at 1 ms, the beam long free: a 299 * 16.3/300 cm = 16.2457 cm move,
     settle 14 + 12 + 3 * (16.2457 - 2) us, dwell 10 */
  double d = 299 * 16.3 / 300;
  double settle = 26 + 3 * (d - 2);
  double t3 = beam_dot(&b, 10, 299, 1e-3);
  assert_true(fabs(t3 - (1e-3 + (settle + 10) * 1e-6)) < 1e-12);
  assert_true(fabs(beam_tube_seconds(&b) - (10 + 27.15 + settle + 10) * 1e-6) < 1e-12);
  assert_true(fabs(beam_total_seconds(&b) - t3) < 1e-15);
  assert_int_equal(beam_dots(&b), 3);
  /* computing that goes on after the last dot makes the picture complete later */
  beam_clock(&b, 2e-3);
  assert_true(fabs(beam_total_seconds(&b) - 2e-3) < 1e-15);
  assert_true(fabs(beam_tube_seconds(&b) - (10 + 27.15 + settle + 10) * 1e-6) < 1e-12);
}

static void test_beam_params(void **state)
{
  (void)state;
  struct beam_params p;
  struct t74_error err = { T74_OK, "" };
  beam_params_default(&p);
  for (int k = 0; k < BP_NPARAM; k++) {           /* every row has a source */
    assert_non_null(beam_param_rows[k].source);
    assert_true(strlen(beam_param_rows[k].source) > 5);
  }
  assert_true(strstr(beam_param_rows[BP_DWELL_US].source, "inferred") != NULL);
  assert_int_equal(beam_params_set(&p, "dwell_us=20", &err), T74_OK);
  assert_true(p.v[BP_DWELL_US] == 20);
  struct beam b;
  beam_init(&b, &p);
  assert_true(fabs(beam_dot(&b, 0, 0, 0) - 20e-6) < 1e-12);
  assert_int_equal(beam_params_set(&p, "dwell_us=-1", &err), T74_EINPUT);
  err.status = T74_OK;
  assert_int_equal(beam_params_set(&p, "nosuch=1", &err), T74_EINPUT);
  err.status = T74_OK;
  assert_int_equal(beam_params_set(&p, "home_x=1.5", &err), T74_EINPUT);
  assert_true(p.v[BP_DWELL_US] == 20);            /* a failed set changes nothing */
}

/* ---- look helpers ------------------------------------------------------------------ */

/* The look's defaults with no glow, so a picture is its dots alone. */
static struct look_params params_noglow(void)
{
  struct look_params p;
  look_params_default(&p);
  p.v[LP_GLOW] = 0;
  return p;
}

static float *intensity(const struct look *l, double t, int s)
{
  float *I = malloc((size_t)TUBE_W * s * (size_t)TUBE_H * s * sizeof *I);
  assert_non_null(I);
  assert_int_equal(look_intensity(l, t, s, I), T74_OK);
  return I;
}

/* Light of a picture: sum of intensity times pixel area (mm^2). */
static double energy(const float *I, int s, const struct look_params *p)
{
  double sum = 0;
  for (size_t k = 0; k < (size_t)TUBE_W * s * (size_t)TUBE_H * s; k++) sum += I[k];
  return sum * (p->v[LP_PITCH_X_MM] / s) * (p->v[LP_PITCH_Y_MM] / s);
}

/* Mean of a unit-peak Gaussian (sigma) over [u0, u1] (mm). */
static double gmean(double sigma, double u0, double u1)
{
  return sigma * sqrt(PI / 2) / (u1 - u0) * (erf(u1 / (sigma * sqrt(2))) - erf(u0 / (sigma * sqrt(2))));
}

/* ---- look -------------------------------------------------------------------------- */

static void test_spot_profile_energy(void **state)
{
  (void)state;
  struct look_params p = params_noglow();
  struct look *l = look_new(&p, 0);
  assert_non_null(l);
  assert_int_equal(look_dot(l, 200, 150, 0.0), T74_OK);
  double sig = p.v[LP_SPOT_MM];
  double e_want = p.v[LP_STORED] * 2 * PI * sig * sig;
  /* the spot is sized from the pitch: its light equals a pitch cell at the stored level */
  assert_true(fabs(e_want - p.v[LP_STORED] * p.v[LP_PITCH_X_MM] * p.v[LP_PITCH_Y_MM]) < 1e-3 * e_want);
  for (int s = 1; s <= LOOK_SCALE_MAX; s++) {
    float *I = intensity(l, 5.0, s);
    int W = TUBE_W * s;
    double e = energy(I, s, &p);
    assert_true(fabs(e - e_want) < 1e-4 * e_want);
    /* the brightest pixel is inside the dot's own s x s block (x 200, row 299-150) */
    size_t best = 0;
    for (size_t k = 0; k < (size_t)W * TUBE_H * s; k++) if (I[k] > I[best]) best = k;
    int bx = (int)(best % (size_t)W), by = (int)(best / (size_t)W);
    assert_true(bx >= 200 * s && bx < 201 * s);
    assert_true(by >= 149 * s && by < 150 * s);
    /* every pixel is the pixel mean of the Gaussian: check a row through the centre */
    double px = p.v[LP_PITCH_X_MM] / s, py = p.v[LP_PITCH_Y_MM] / s;
    double cx = (200 + 0.5) * s, cy = (149 + 0.5) * s;       /* centre, pixel units */
    for (int X = 200 * s - 3 * s; X < 201 * s + 3 * s; X++) {
      int Y = 149 * s;
      double want = p.v[LP_STORED] * gmean(sig, (X - cx) * px, (X + 1 - cx) * px) *
                    gmean(sig, (Y - cy) * py, (Y + 1 - cy) * py);
      assert_true(fabs(I[(size_t)Y * W + X] - want) < 1e-5);
    }
    /* symmetric about the centre */
    for (int d = 0; d < 3 * s; d++) {
      size_t row = (size_t)(149 * s) * W;
      assert_true(fabs(I[row + 200 * s - 1 - d] - I[row + 201 * s + d]) < 1e-6);
    }
    free(I);
  }
  look_free(l);
}

static void test_solid_area_level(void **state)
{
  (void)state;
  /* every dot of a 40 x 40 patch lit: averaged over a dot's cell the middle shines at the
     stored level (the spot's light is one pitch cell's worth); within the cell the dots
     still show, brighter at their centres than between them */
  struct look_params p = params_noglow();
  struct look *l = look_new(&p, 0);
  for (int y = 100; y < 140; y++)
    for (int x = 100; x < 140; x++) assert_int_equal(look_dot(l, x, y, 0), T74_OK);
  int s = 4, W = TUBE_W * s;
  float *I = intensity(l, 1.0, s);
  double sum = 0;
  for (int Y = (299 - 120) * s; Y < (300 - 120) * s; Y++)
    for (int X = 120 * s; X < 121 * s; X++) sum += I[(size_t)Y * W + X];
  assert_true(fabs(sum / (s * s) - p.v[LP_STORED]) < 1e-3 * p.v[LP_STORED]);
  float centre = I[(size_t)((299 - 120) * s + 2) * W + 120 * s + 2];
  float corner = I[(size_t)((299 - 120) * s) * W + 120 * s];
  assert_true(centre > corner);
  free(I);
  look_free(l);
}

static void test_glow(void **state)
{
  (void)state;
  struct look_params p;
  look_params_default(&p);
  assert_true(p.v[LP_GLOW] == 0.08);             /* rricharz/Tek4010 */
  struct look *l = look_new(&p, LOOK_FLASH);
  for (double t = 0; t < 100; t += 33) {         /* no dots: glow alone, steady */
    float *I = intensity(l, t, 2);
    for (size_t k = 0; k < (size_t)TUBE_W * 2 * TUBE_H * 2; k++)
      assert_true(fabs(I[k] - 0.08) < 1e-6);
    free(I);
  }
  look_free(l);
}

static void test_flash_decay(void **state)
{
  (void)state;
  struct look_params p = params_noglow();
  struct look *l = look_new(&p, LOOK_FLASH);
  look_dot(l, 50, 60, 2.0);
  double unit = 2 * PI * p.v[LP_SPOT_MM] * p.v[LP_SPOT_MM];   /* light of a unit-peak spot */
  double ages[] = { 0, 0.1, 0.25, 0.5, 0.9, 1.0, 1.5, 30 };
  for (size_t k = 0; k < sizeof ages / sizeof *ages; k++) {
    double a = ages[k];
    double amp = p.v[LP_STORED];
    if (a < p.v[LP_FLASH_S]) amp += (p.v[LP_BRIGHT] - p.v[LP_STORED]) * (1 - a / p.v[LP_FLASH_S]);
    float *I = intensity(l, 2.0 + a, 1);
    assert_true(fabs(energy(I, 1, &p) - amp * unit) < 1e-4 * unit);
    free(I);
  }
  /* before it is written: nothing */
  float *I = intensity(l, 1.999, 1);
  assert_true(energy(I, 1, &p) == 0);
  free(I);
  /* settled: the last event plus its flash */
  assert_true(fabs(look_settled(l) - 3.0) < 1e-12);
  look_free(l);
}

static void test_writethrough(void **state)
{
  (void)state;
  struct look_params p = params_noglow();
  struct look *l = look_new(&p, 0);
  look_writethrough(l, 10, 10, 0);
  double unit = 2 * PI * p.v[LP_SPOT_MM] * p.v[LP_SPOT_MM];
  double wt = p.v[LP_WRITETHRU_S];
  for (double a = 0; a < wt; a += wt / 4) {
    float *I = intensity(l, a, 1);
    double want = p.v[LP_WRITETHRU] * (1 - a / wt) * unit;
    assert_true(fabs(energy(I, 1, &p) - want) < 1e-4 * unit);
    free(I);
  }
  float *I = intensity(l, wt * 1.01, 1);      /* not stored: gone */
  assert_true(energy(I, 1, &p) == 0);
  free(I);
  assert_int_equal(look_count(l), 0);         /* not a stored dot */
  assert_true(p.v[LP_WRITETHRU] < p.v[LP_STORED]);   /* dim */
  look_free(l);
}

static void test_erase(void **state)
{
  (void)state;
  struct look_params p;
  look_params_default(&p);
  double D = p.v[LP_ERASE_S], glow = p.v[LP_GLOW];
  assert_true(D < 0.5);                        /* paper 003: erases in under 500 ms */
  struct look *l = look_new(&p, 0);
  look_dot(l, 100, 100, 0.5);
  look_erase(l, 1.0);
  look_dot(l, 300, 200, 1.0 + D + 0.1);       /* written after the erase: stays */
  size_t far = (size_t)(10) * TUBE_W + 10;    /* a pixel far from both dots */
  size_t dot1 = (size_t)(299 - 100) * TUBE_W + 100;
  /* before: the dot and the glow */
  float *I = intensity(l, 0.9, 1);
  assert_true(fabs(I[far] - glow) < 1e-6);
  assert_true(I[dot1] > 0.3);
  free(I);
  /* during: the whole face flashes, linearly dying away */
  for (double u = 0; u < 1; u += 0.25) {
    I = intensity(l, 1.0 + u * D, 1);
    assert_true(fabs(I[far] - (glow + p.v[LP_ERASE_LEVEL] * (1 - u))) < 1e-5);
    free(I);
  }
  /* after erase_s: cleared, only the glow (the later dot not yet written) */
  I = intensity(l, 1.0 + D, 1);
  for (size_t k = 0; k < (size_t)TUBE_W * TUBE_H; k++) assert_true(fabs(I[k] - glow) < 1e-6);
  free(I);
  /* the dot written after the erase is there */
  I = intensity(l, 1.0 + D + 0.2, 1);
  assert_true(I[(size_t)(299 - 200) * TUBE_W + 300] > 0.3);
  assert_true(fabs(I[dot1] - glow) < 1e-6);
  free(I);
  look_free(l);
}

static void test_fade_only_when_asked(void **state)
{
  (void)state;
  struct look_params p = params_noglow();
  struct look *still = look_new(&p, LOOK_FLASH);
  struct look *fading = look_new(&p, LOOK_FADE);
  look_dot(still, 200, 150, 0);
  look_dot(fading, 200, 150, 0);
  size_t n = (size_t)TUBE_W * 2 * TUBE_H * 2;
  /* without LOOK_FADE the stored picture does not change, however long it waits */
  float *a = intensity(still, 2, 2), *b = intensity(still, 1e5, 2);
  assert_memory_equal(a, b, n * sizeof *a);
  free(b);
  /* with LOOK_FADE: the same light spread wider, dimmed by exp(-age / fade_s) */
  double F = p.v[LP_FADE_S], unit = 2 * PI * p.v[LP_SPOT_MM] * p.v[LP_SPOT_MM];
  float *c = intensity(fading, 0, 2);
  assert_memory_equal(a, c, n * sizeof *a);   /* at age 0 it is the plain spot */
  free(c);
  double ages[] = { F / 4, F, 2 * F };
  for (int k = 0; k < 3; k++) {
    c = intensity(fading, ages[k], 2);
    double want = p.v[LP_STORED] * unit * exp(-ages[k] / F);
    assert_true(fabs(energy(c, 2, &p) - want) < 1e-3 * want);
    /* and wider: the peak drops more than the energy */
    float peak = 0;
    for (size_t i = 0; i < n; i++) if (c[i] > peak) peak = c[i];
    float peak0 = 0;
    for (size_t i = 0; i < n; i++) if (a[i] > peak0) peak0 = a[i];
    assert_true(peak / peak0 < exp(-ages[k] / F) * 0.999);
    free(c);
  }
  free(a);
  look_free(still);
  look_free(fading);
}

static void test_params_and_colour(void **state)
{
  (void)state;
  struct look_params p;
  struct t74_error err = { T74_OK, "" };
  look_params_default(&p);
  for (int k = 0; k < LP_NPARAM; k++) assert_true(strlen(look_param_rows[k].source) > 5);
  assert_true(p.v[LP_STORED] == 0.7 && p.v[LP_WRITETHRU] == 0.5 && p.v[LP_BRIGHT] == 1.0);
  assert_true(p.v[LP_FLASH_S] == 1.0);
  assert_int_equal(look_params_set(&p, "glow=0.1", &err), T74_OK);
  assert_true(p.v[LP_GLOW] == 0.1);
  assert_int_equal(look_params_set(&p, "glow=x", &err), T74_EINPUT);
  err.status = T74_OK;
  assert_int_equal(look_params_set(&p, "erase_s=-1", &err), T74_EINPUT);
  look_params_default(&p);
  uint8_t c[4];
  look_colour(&p, 0, c);
  assert_true(c[0] == 0 && c[1] == 0 && c[2] == 0 && c[3] == 255);
  look_colour(&p, 0.7f, c);                    /* stored: P1 green */
  assert_int_equal(c[1], (int)lrint(0.7 * 255));
  assert_true(c[0] < c[1] && c[2] < c[1]);
  look_colour(&p, 3.0f, c);                    /* far over 1: whitened to full */
  assert_true(c[0] == 255 && c[1] == 255 && c[2] == 255);
  /* scale out of range */
  struct look *l = look_new(&p, 0);
  float f;
  assert_int_equal(look_intensity(l, 0, 0, &f), T74_EINPUT);
  assert_int_equal(look_intensity(l, 0, LOOK_SCALE_MAX + 1, &f), T74_EINPUT);
  assert_int_equal(look_dot(l, 400, 0, 0), T74_EINPUT);
  assert_int_equal(look_dot(l, 0, -1, 0), T74_EINPUT);
  look_free(l);
}

static void test_png(void **state)
{
  (void)state;
  char dir[] = "/tmp/t74look.XXXXXX";
  assert_non_null(mkdtemp(dir));
  char path[64];
  snprintf(path, sizeof path, "%s/a.png", dir);
  struct look_params p;
  look_params_default(&p);
  struct look *l = look_new(&p, LOOK_FLASH);
  look_dot(l, 1, 1, 0);
  struct t74_error err = { T74_OK, "" };
  assert_int_equal(look_write_png(l, 0.5, 3, path, &err), T74_OK);
  FILE *f = fopen(path, "rb");
  assert_non_null(f);
  unsigned char h[24];
  assert_int_equal(fread(h, 1, 24, f), 24);
  fclose(f);
  assert_memory_equal(h, "\x89PNG\r\n\x1a\n", 8);
  /* IHDR width and height (big-endian) at bytes 16..23: 1200 x 900 */
  assert_int_equal((h[16] << 24) | (h[17] << 16) | (h[18] << 8) | h[19], 1200);
  assert_int_equal((h[20] << 24) | (h[21] << 16) | (h[22] << 8) | h[23], 900);
  /* a bad scale leaves no file */
  snprintf(path, sizeof path, "%s/b.png", dir);
  assert_int_equal(look_write_png(l, 0.5, 9, path, &err), T74_EINPUT);
  assert_int_equal(access(path, F_OK), -1);
  snprintf(path, sizeof path, "%s/a.png", dir);
  unlink(path);
  rmdir(dir);
  look_free(l);
}


/* A wide faded spot goes onto a coarse grid (look.c "wide spots"): its light and its
** profile stay those of the exact spot, within the 2% the file head promises, at every
** scale; and a spot faded below what a pixel can show is not drawn at all. */
static void test_wide_spot_on_a_coarse_grid(void **state)
{
  (void)state;
  struct look_params p = params_noglow();
  p.v[LP_FADE_S] = 1;
  p.v[LP_FADE_SPREAD_MM] = 10;                   /* the largest spread */
  struct look *l = look_new(&p, LOOK_FADE);
  assert_non_null(l);
  assert_int_equal(look_dot(l, 200, 150, 0.0), T74_OK);
  double spot2 = p.v[LP_SPOT_MM] * p.v[LP_SPOT_MM];
  double sig2 = spot2 + 100 * 1.0, sig = sqrt(sig2);           /* age 1 fade time */
  double amp = p.v[LP_STORED] * spot2 / sig2 * exp(-1.0);
  double e_want = amp * 2 * PI * sig2;
  int scales[] = { 1, 4, 8 };
  for (int k = 0; k < 3; k++) {
    int s = scales[k], W = TUBE_W * s, H = TUBE_H * s;
    float *I = intensity(l, 1.0, s);
    assert_true(fabs(energy(I, s, &p) - e_want) < 0.01 * e_want);
    double px = p.v[LP_PITCH_X_MM] / s, py = p.v[LP_PITCH_Y_MM] / s;
    double cx = (200 + 0.5) * s, cy = (149 + 0.5) * s;
    for (int X = 0; X < W; X += 1 + s / 4) {     /* the row and column through the dot */
      int Y = 149 * s;
      double want = amp * gmean(sig, (X - cx) * px, (X + 1 - cx) * px) *
                    gmean(sig, (Y - cy) * py, (Y + 1 - cy) * py);
      if (fabs(I[(size_t)Y * W + X] - want) >= 0.02 * amp)
        fail_msg("scale %d, x %d: %g, exact %g (peak %g)", s, X, I[(size_t)Y * W + X], want, amp);
    }
    for (int Y = 0; Y < H; Y += 1 + s / 4) {
      int X = 200 * s;
      double want = amp * gmean(sig, (X - cx) * px, (X + 1 - cx) * px) *
                    gmean(sig, (Y - cy) * py, (Y + 1 - cy) * py);
      assert_true(fabs(I[(size_t)Y * W + X] - want) < 0.02 * amp);
    }
    free(I);
  }
  /* ten fade times later its peak is e^-10 of a dim spread: nothing is drawn */
  float *I = intensity(l, 10.0, 1);
  assert_true(energy(I, 1, &p) == 0);
  free(I);
  look_free(l);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_settle_613),
    cmocka_unit_test(test_beam_sequence),
    cmocka_unit_test(test_beam_params),
    cmocka_unit_test(test_spot_profile_energy),
    cmocka_unit_test(test_solid_area_level),
    cmocka_unit_test(test_glow),
    cmocka_unit_test(test_flash_decay),
    cmocka_unit_test(test_writethrough),
    cmocka_unit_test(test_erase),
    cmocka_unit_test(test_fade_only_when_asked),
    cmocka_unit_test(test_wide_spot_on_a_coarse_grid),
    cmocka_unit_test(test_params_and_colour),
    cmocka_unit_test(test_png),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
