/* The report's arithmetic (cli/report_math.h): the Pareto front of a
 * crafted set of points, the gains and summary against hand values, the
 * sweep syntax with its errors, and sequences (views grouped into runs, a
 * setting's mean error, flicker and lag over one) on synthetic data. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <string.h>

#include "report_math.h"

/* Points (ms, error), lower is better in both:
 *   0 (1, 10)  front: fastest
 *   1 (2, 5)   front
 *   2 (3, 6)   dominated by 1
 *   3 (4, 2)   front
 *   4 (4, 2)   front: equal to 3, neither dominates
 *   5 (5, 2)   dominated by 3 (same error, slower)
 *   6 (6, 1)   front: most accurate
 *   7 (2, 7)   dominated by 1 (same time, worse error) */
static void pareto_crafted(void **state) {
  (void)state;
  double ms[] = {1, 2, 3, 4, 4, 5, 6, 2}, err[] = {10, 5, 6, 2, 2, 2, 1, 7};
  bool front[8];
  report_pareto(ms, err, 8, front);
  bool want[] = {true, true, false, true, true, false, true, false};
  for (int i = 0; i < 8; i++) assert_int_equal(front[i], want[i]);
  /* One point is its own front; none is fine. */
  report_pareto(ms, err, 1, front);
  assert_true(front[0]);
  report_pareto(ms, err, 0, front);
}

static void gains_by_hand(void **state) {
  (void)state;
  assert_float_equal(report_gain(0.1, 0.09), 10.0, 1e-9);
  assert_float_equal(report_gain(0.2, 0.25), -25.0, 1e-9);
  assert_float_equal(report_gain(0.0, 0.1), 0.0, 0); /* nothing to gain: defined, not Inf */
  /* Four views. Baseline errors 0.1 0.2 0.4 0.5, the setting's 0.09 0.25 0.3
   * 0.5: gains 10, -25, 25, 0; mean 2.5, median (0 + 10) / 2 = 5; improved
   * 2 of 4. Pixels closer 0.5, 0.1, 0.9, 0 of 100, 100, 200, 100 pixels:
   * (50 + 10 + 180 + 0) / 500 = 0.48. Pearson means 0.8 and 0.85. */
  double base[] = {0.1, 0.2, 0.4, 0.5}, e[] = {0.09, 0.25, 0.3, 0.5}, closer[] = {0.5, 0.1, 0.9, 0};
  double px[] = {100, 100, 200, 100}, pb[] = {0.7, 0.8, 0.9, 0.8}, pa[] = {0.8, 0.8, 0.9, 0.9};
  /* Direct-only floors 0.05 0.1 0.4 0.1: indirect errors 0.05 0.1 (none) 0.4;
   * removed 20, -50, n/a, 0: mean over the three views -10. */
  double fl[] = {0.05, 0.1, 0.4, 0.1};
  report_summary s;
  report_summarize(4, base, fl, e, closer, px, pb, pa, &s);
  assert_int_equal(s.views, 4);
  assert_float_equal(s.mean_gain, 2.5, 1e-9);
  assert_float_equal(s.median_gain, 5.0, 1e-9);
  assert_float_equal(s.views_improved, 0.5, 1e-12);
  assert_float_equal(s.pixels_closer, 0.48, 1e-12);
  assert_float_equal(s.pearson_before, 0.8, 1e-12);
  assert_float_equal(s.pearson_after, 0.85, 1e-12);
  assert_float_equal(s.views_pearson_rose, 0.5, 1e-12); /* views 0 and 3 */
  assert_int_equal(s.indirect_views, 3);
  assert_float_equal(s.indirect_removed, -10.0, 1e-9);
  assert_float_equal(s.floor, 0.1625, 1e-12);
  /* An odd count takes the middle gain. */
  report_summarize(3, base, fl, e, closer, px, pb, pa, &s);
  assert_float_equal(s.median_gain, 10.0, 1e-9);
  assert_float_equal(s.mean_gain, 10.0 / 3.0, 1e-9);
  assert_int_equal(s.indirect_views, 2);
  assert_float_equal(s.indirect_removed, -15.0, 1e-9);
  report_summarize(0, base, fl, e, closer, px, pb, pa, &s);
  assert_int_equal(s.views, 0);
  assert_float_equal(s.mean_gain, 0, 0);
  assert_int_equal(s.indirect_views, 0);
  assert_float_equal(s.indirect_removed, 0, 0);
}

/* The share of indirect error removed: by hand, and n/a (false, the output
 * untouched) when the floor is not below the baseline: never a division by 0. */
static void indirect_share_by_hand(void **state) {
  (void)state;
  double v = 123;
  assert_true(report_indirect_removed(0.04, 0.01, 0.025, &v));
  assert_float_equal(v, 50.0, 1e-9);
  assert_true(report_indirect_removed(0.04, 0.01, 0.01, &v));
  assert_float_equal(v, 100.0, 1e-9); /* down to the floor: all of it */
  assert_true(report_indirect_removed(0.04, 0.01, 0.05, &v));
  assert_float_equal(v, -100.0 / 3.0, 1e-9);
  v = 123;
  assert_false(report_indirect_removed(0.04, 0.04, 0.03, &v));
  assert_false(report_indirect_removed(0.04, 0.05, 0.03, &v));
  assert_false(report_indirect_removed(0, 0, 0, &v));
  assert_float_equal(v, 123, 0);
}

static void sweep_syntax(void **state) {
  (void)state;
  static report_setting list[REPORT_MAX_SETTINGS];
  int n = 0;
  lm_error err;
  assert_true(report_sweep_parse("dl", list, &n, &err));
  assert_int_equal(n, 1);
  assert_string_equal(list[0].technique, "dl");
  assert_int_equal(list[0].option_count, 0);
  assert_true(report_sweep_parse("isr:isr.samples=8,16,32;isr.coarse=1,2", list, &n, &err));
  assert_int_equal(n, 7); /* 3 x 2 more */
  assert_string_equal(list[1].technique, "isr");
  assert_string_equal(list[1].names[0], "isr.samples");
  assert_string_equal(list[1].values[0], "8");
  assert_string_equal(list[1].values[1], "1");
  assert_string_equal(list[2].values[0], "8"); /* the last option varies fastest */
  assert_string_equal(list[2].values[1], "2");
  assert_string_equal(list[6].values[0], "32");
  assert_string_equal(list[6].values[1], "2");
  assert_string_equal(list[6].label, "isr samples=32 coarse=2");
  assert_true(report_sweep_parse(" ssao : ssao.radius = 0.1 , 0.2 ", list, &n, &err));
  assert_int_equal(n, 9);
  assert_string_equal(list[8].technique, "ssao");
  assert_string_equal(list[8].values[0], "0.2");
  /* Errors name the spec and leave the list as it was. */
  const char *bad[] = {"", ":a=1", "isr:samples", "isr:=1", "isr:a=1,,2", "isr:a=", "a=1"};
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    assert_false(report_sweep_parse(bad[i], list, &n, &err));
    assert_non_null(strstr(err.msg, "--sweep"));
    assert_int_equal(n, 9);
  }
  /* More settings than a report holds. */
  assert_false(report_sweep_parse("isr:a=1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16;b=1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16",
                                  list, &n, &err));
  assert_non_null(strstr(err.msg, "more than"));
  assert_int_equal(n, 9);
  /* A setting given twice, within a sweep or by a second one, is refused naming it. */
  assert_false(report_sweep_parse("isr:isr.samples=4,8,8", list, &n, &err));
  assert_non_null(
      strstr(err.msg, "--sweep 'isr:isr.samples=4,8,8': setting 'isr samples=8' is there twice (settings 10 and 11)"));
  assert_int_equal(n, 9);
  assert_false(report_sweep_parse("ssao:ssao.radius=0.2", list, &n, &err));
  assert_non_null(strstr(err.msg, "setting 'ssao radius=0.2' is there twice (settings 8 and 9)"));
  assert_int_equal(n, 9);
}

/* Views as a job lists them: camera 0 in frames 0 1 2, camera 1 in frames
 * 0 1 2, then a still view of scene 1, then the same place again at frame 0
 * (not after the last: a new run), then another technique's frame 1. */
static void views_group_into_sequences(void **state) {
  (void)state;
  job_view v[9] = {
      {.camera = 0, .frame = 0}, {.camera = 0, .frame = 1}, {.camera = 0, .frame = 2},
      {.camera = 1, .frame = 0}, {.camera = 1, .frame = 1}, {.camera = 1, .frame = 2},
      {.scene = 1, .frame = 0},  {.scene = 1, .frame = 0},  {.scene = 1, .technique = 1, .frame = 1},
  };
  int first[10];
  assert_int_equal(report_sequences(v, 9, first), 5);
  int want[] = {0, 3, 6, 7, 8, 9};
  for (int i = 0; i < 6; i++) assert_int_equal(first[i], want[i]);
  /* A still job: every view its own run. */
  job_view still[3] = {{.camera = 0}, {.camera = 1}, {.size = 1}};
  assert_int_equal(report_sequences(still, 3, first), 3);
  assert_int_equal(first[3], 3);
  assert_int_equal(report_sequences(still, 0, first), 0);
  assert_int_equal(first[0], 0);
}

/* Ten frames, events at frames 1 and 3. Errors 0.1 0.1 0.1 then the step
 * 0.6 0.4 0.21 0.2 0.2 0.2 0.2: mean 2.31 / 10. Event 1's window is frames
 * 1 .. 2, flat: lag 0. Event 3's is frames 3 .. 9, settled the median of
 * 0.21 0.2 0.2 0.2 0.2 = 0.2, tolerance 0.02: 0.21 is back, 0.4 is not, so
 * the lag is 2. Flicker is the mean over the nine pairs: 0.1 / 9. */
static void sequence_summary_by_hand(void **state) {
  (void)state;
  double error[] = {0.1, 0.1, 0.1, 0.6, 0.4, 0.21, 0.2, 0.2, 0.2, 0.2};
  double flicker[] = {NAN /* not read */, 0.01, 0.02, 0.03, 0, 0, 0, 0, 0, 0.04};
  int events[] = {1, 3};
  report_sequence s;
  lm_error err;
  assert_true(report_sequence_summarize(10, error, flicker, events, NULL, 2, &s, &err));
  assert_int_equal(s.frames, 10);
  assert_float_equal(s.mean_error, 0.231, 1e-12);
  assert_float_equal(s.flicker, 0.1 / 9, 1e-12);
  assert_int_equal(s.event_count, 2);
  assert_int_equal(s.lags[0].frames, 0);
  assert_true(s.lags[0].returned);
  assert_float_equal(s.lags[0].settled, 0.1, 1e-12);
  assert_int_equal(s.lags[1].frames, 2);
  assert_true(s.lags[1].returned);
  assert_float_equal(s.lags[1].settled, 0.2, 1e-12);
  /* Event 3 against a converged error of 0.3 (given): 0.21 and 0.2 are off
   * by more than 0.03 from frame 5 on, so it never returns. */
  double settled[] = {-1, 0.3};
  assert_true(report_sequence_summarize(10, error, flicker, events, settled, 2, &s, &err));
  assert_float_equal(s.lags[0].settled, 0.1, 1e-12);
  assert_false(s.lags[1].returned);
  assert_int_equal(s.lags[1].frames, 7);
  /* No events: no lags; one frame: flicker 0, not 0/0. */
  assert_true(report_sequence_summarize(1, error, flicker, NULL, NULL, 0, &s, &err));
  assert_int_equal(s.event_count, 0);
  assert_float_equal(s.flicker, 0, 0);
  assert_float_equal(s.mean_error, 0.1, 1e-12);
  /* A non-finite value is refused naming its frame. */
  error[4] = INFINITY;
  assert_false(report_sequence_summarize(10, error, flicker, events, NULL, 2, &s, &err));
  assert_non_null(strstr(err.msg, "frame 4:"));
  error[4] = 0.4;
  flicker[7] = NAN;
  assert_false(report_sequence_summarize(10, error, flicker, NULL, NULL, 0, &s, &err));
  assert_non_null(strstr(err.msg, "frame 7:"));
}

static void events_are_checked(void **state) {
  (void)state;
  lm_error err;
  int ok[] = {0, 12, 30}, late[] = {12, 48}, back[] = {30, 12}, same[] = {5, 5};
  assert_true(report_events_check("job.lua", ok, 3, 48, &err));
  assert_true(report_events_check("job.lua", ok, 0, 48, &err));
  assert_false(report_events_check("job.lua", late, 2, 48, &err));
  assert_string_equal(err.msg, "job.lua: events[2]: frame 48 is not among the sequence's frames 0 .. 47");
  assert_false(report_events_check("job.lua", back, 2, 48, &err));
  assert_string_equal(err.msg, "job.lua: events[2]: frame 12 does not come after frame 30 (events go in order)");
  assert_false(report_events_check("job.lua", same, 2, 48, &err));
}

/* Two runs of 3 and 2 frames: frame 2 has one run, so its mean is its value. */
static void frame_curve_by_hand(void **state) {
  (void)state;
  double a[] = {1, 2, 3}, b[] = {3, 4}, curve[3];
  const double *errors[] = {a, b};
  int frames[] = {3, 2};
  assert_int_equal(report_frame_curve(errors, frames, 2, curve), 3);
  assert_float_equal(curve[0], 2, 0);
  assert_float_equal(curve[1], 3, 0);
  assert_float_equal(curve[2], 3, 0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(pareto_crafted),
      cmocka_unit_test(gains_by_hand),
      cmocka_unit_test(indirect_share_by_hand),
      cmocka_unit_test(sweep_syntax),
      cmocka_unit_test(views_group_into_sequences),
      cmocka_unit_test(sequence_summary_by_hand),
      cmocka_unit_test(events_are_checked),
      cmocka_unit_test(frame_curve_by_hand),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
