#!/usr/bin/python3
"""test_bench_summary.py — the verdicts of `murk bench`'s generated summary (tools/bench_report.py).

A ratio of efficiencies within RESOLVED_SE standard errors of 1 is no measured difference: the summary must
say that no variant is measurably more efficient (the issue's case: two variants that make the same
decisions, 1 ± 0.053x, 0.0 standard errors), and name a winner only when the ratio is resolved. The load
line says when the load average exceeded the cores."""
import os
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tools"))
import bench_report  # noqa: E402


def meta(nv=2, load=None):
    m = {"variants": ["type=delta", "type=spectral_mis"][:nv] + ["type=x%d" % i for i in range(nv - 2)],
         "budget": "spp", "repeat": 4, "cores": 2,
         "reference": {"noise_estimated": False, "path": "ref.exr", "spp": 0}}
    if load:
        m["load"] = load
    return m


def cell(relmse, se, seconds=10.0, sec_se=0.1):
    z = (0.0, 0.0)
    return {"relmse": (relmse, se), "seconds": (seconds, sec_se), "lookups": (1e6, 0.0), "rays": z,
            "relmse_raw": (relmse, se), "ref_noise": z, "spp": (64, 0), "nonfinite": z, "max_sample": z,
            "collisions": z}


class Summary(unittest.TestCase):
    def test_same_decisions_is_no_difference(self):
        agg = {0: {64: cell(0.01, 0.0003)}, 1: {64: cell(0.01, 0.0003)}}
        s = bench_report.summary(meta(), agg, None)
        self.assertIn("no variant is measurably more efficient", s)
        self.assertNotIn("is the most efficient", s)

    def test_small_lead_is_no_difference(self):  # 1.05x at 0.053 se: within 2 se
        agg = {0: {64: cell(0.0105, 0.0004)}, 1: {64: cell(0.0100, 0.0004)}}
        s = bench_report.summary(meta(), agg, None)
        self.assertIn("no variant is measurably more efficient than 'type=delta'", s)

    def test_resolved_winner(self):  # twice as efficient, a few percent error: a verdict
        agg = {0: {64: cell(0.02, 0.0004)}, 1: {64: cell(0.01, 0.0002)}}
        s = bench_report.summary(meta(), agg, None)
        self.assertIn("'type=spectral_mis' is the most efficient", s)
        self.assertNotIn("no variant is measurably", s)

    def test_resolved_first(self):
        agg = {0: {64: cell(0.01, 0.0002)}, 1: {64: cell(0.02, 0.0004)}}
        s = bench_report.summary(meta(), agg, None)
        self.assertIn("'type=delta' (the first variant) is the most efficient", s)

    def test_one_seed_no_verdict(self):
        agg = {0: {64: cell(0.02, float("nan"), sec_se=float("nan"))},
               1: {64: cell(0.01, float("nan"), sec_se=float("nan"))}}
        s = bench_report.summary(meta(), agg, None)
        self.assertIn("no difference is resolved", s)

    def test_load_line(self):
        busy = bench_report.load_line(meta(load={"before": [5.2, 4, 3], "after": [6.1, 5, 4]}))
        self.assertIn("above the 2 cores", busy)
        idle = bench_report.load_line(meta(load={"before": [0.5, 0.4, 0.3], "after": [1.9, 1, 1]}))
        self.assertNotIn("above", idle)
        self.assertIn("not recorded", bench_report.load_line(meta()))


if __name__ == "__main__":
    unittest.main()
