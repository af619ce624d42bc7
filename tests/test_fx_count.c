/*
** test_fx_count.c — cmocka tests of effects/fx.c's fx_count, the effects' named statistics
** (--stats prints them in the order first counted).
**
** fx_count finds a name again by a hash of its characters (hash[]), confirmed by strcmp.
** It must give what the string compare alone gave: the same name through another pointer
** (a copy in a buffer) adds to its figure; names with a common prefix, or one another's
** prefix, stay apart; a buffer counted under one name and then filled with another is
** counted under the other; a name longer than FX_NAME_MAX - 1 is cut as snprintf cut it
** and never found again; no more than FX_MAX_COUNTERS names are kept. Each figure is
** checked against a plain model (strcmp over the stored names, as fx_count was).
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "effects/fx.h"

/* name's first FX_NAME_MAX - 1 characters into to, as snprintf(to, FX_NAME_MAX, "%s") */
static void cut_copy(char *to, const char *name)
{
  size_t l = strlen(name);
  if (l > FX_NAME_MAX - 1) l = FX_NAME_MAX - 1;
  memcpy(to, name, l);
  to[l] = '\0';
}

/* the model: fx_count as it was (strcmp, then snprintf) */
struct model { int n; char name[FX_MAX_COUNTERS][FX_NAME_MAX]; double value[FX_MAX_COUNTERS];
               bool integer[FX_MAX_COUNTERS]; };

static void model_count(struct model *m, const char *name, double v, bool integer)
{
  for (int k = 0; k < m->n; k++)
    if (!strcmp(m->name[k], name)) { m->value[k] += v; return; }
  if (m->n == FX_MAX_COUNTERS) return;
  cut_copy(m->name[m->n], name);
  m->value[m->n] = v;
  m->integer[m->n] = integer;
  m->n++;
}

static void assert_agree(const struct fx_stats *st, const struct model *m)
{
  assert_int_equal(st->n, m->n);
  for (int k = 0; k < m->n; k++) {
    assert_string_equal(st->name[k], m->name[k]);
    assert_true(st->value[k] == m->value[k]);
    assert_int_equal(st->integer[k], m->integer[k]);
  }
}

static void both(struct fx_stats *st, struct model *m, const char *name, double v, bool integer)
{
  fx_count(st, name, v, integer);
  model_count(m, name, v, integer);
}

static void test_names(void **state)
{
  (void)state;
  struct fx_stats st;
  struct model m;
  memset(&st, 0, sizeof st);
  memset(&m, 0, sizeof m);
  char buf[64];
  both(&st, &m, "aa_samples", 3, true);
  both(&st, &m, "aa_sample", 1, true);          /* a prefix of a name */
  both(&st, &m, "aa_samples2", 2, true);        /* a name its prefix */
  both(&st, &m, "aa_samples", 4, true);         /* the same literal */
  snprintf(buf, sizeof buf, "%s", "aa_samples");
  both(&st, &m, buf, 5, true);                  /* the same name, another pointer */
  both(&st, &m, "aa_samples", 6, true);         /* and back */
  both(&st, &m, "contour_ms", 0.25, false);
  both(&st, &m, buf, 7, true);
  snprintf(buf, sizeof buf, "%s", "contour_ms");
  both(&st, &m, buf, 0.5, false);               /* the buffer now another counted name */
  snprintf(buf, sizeof buf, "%s", "smooth_points");
  both(&st, &m, buf, 8, true);                  /* the buffer now a new name */
  both(&st, &m, "smooth_points", 9, true);
  both(&st, &m, "", 1, true);                   /* the empty name */
  both(&st, &m, "", 2, true);
  /* too long: cut, and never found again (each count a new entry, as before) */
  const char *longname = "a_name_of_fifty_characters_that_is_too_long_to_keep";
  assert_true(strlen(longname) > FX_NAME_MAX - 1);
  both(&st, &m, longname, 10, true);
  both(&st, &m, longname, 11, true);
  char cut[FX_NAME_MAX];
  cut_copy(cut, longname);
  both(&st, &m, cut, 12, true);                 /* the cut name itself is found */
  /* exactly FX_NAME_MAX - 1 characters: kept whole, found again */
  char whole[FX_NAME_MAX];
  memset(whole, 'x', FX_NAME_MAX - 1);
  whole[FX_NAME_MAX - 1] = '\0';
  both(&st, &m, whole, 13, true);
  both(&st, &m, whole, 14, true);
  assert_agree(&st, &m);
}

static void test_full(void **state)
{
  (void)state;
  struct fx_stats st;
  struct model m;
  memset(&st, 0, sizeof st);
  memset(&m, 0, sizeof m);
  char names[FX_MAX_COUNTERS + 8][16];
  for (int r = 0; r < 3; r++)                   /* rounds: each name found again */
    for (int k = 0; k < FX_MAX_COUNTERS + 8; k++) {
      snprintf(names[k], sizeof names[k], "n%d", k);
      both(&st, &m, names[k], k + r, k % 2);
      both(&st, &m, r ? names[k] : "n0", 1, k % 2);
    }
  assert_int_equal(st.n, FX_MAX_COUNTERS);
  assert_agree(&st, &m);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_names),
    cmocka_unit_test(test_full),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
