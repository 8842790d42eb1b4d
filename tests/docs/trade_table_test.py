#!/usr/bin/env python3
"""scripts/trade-table.py against a hand-worked case: synthetic runs whose means, errors and
differences are worked out below by hand, a variant group among them (U<U_inf>-<variant>-seed<seed>),
and the trades it must refuse. Run: python3 tests/docs/trade_table_test.py (from the repository root)."""
import json, pathlib, subprocess, sys, tempfile, unittest

SCRIPT = pathlib.Path(__file__).resolve().parents[2] / 'scripts' / 'trade-table.py'


def write_run(folder, U_inf, seed, F, F_err):
    """A completed run whose F is given; the other figures the same in every run."""
    same = {'mean': 1.0, 'error': 0.1}
    result = {'status': 'completed', 'derived': {'U_inf': U_inf}, 'case': {'seed': seed},
              'observables': {'F': {'mean': F, 'error': F_err}, 'U_over_Uinf': same, 'C_sph': same,
                              'n_a_mean': same, 'Re_T': same, 'max_liquid_speed': 2 * U_inf,
                              'max_liquid_Mach': 2 * U_inf * 3 ** 0.5,
                              'coupling_oscillation': {'worst_window': 0.0},
                              'mass_balance': {'relative_to_liquid_mass': 1e-15},
                              'momentum_balance': {'relative_to_sphere_momentum': 1e-14},
                              'events': {'worst_overlap': 0.0}},
              'cost': {'steps': 100, 'wall_s': 60.0}}
    folder.mkdir(parents=True)
    (folder / 'result.json').write_text(json.dumps(result))


def trade_table(source):
    return subprocess.run([sys.executable, str(SCRIPT), str(source)], capture_output=True, text=True)


def F_cells(output):
    """{first cell: F cell} of the means table (the second table)."""
    means = output.split('\n\n')[1].splitlines()[2:]
    return {row.split(' | ')[0].lstrip('| '): row.split(' | ')[1] for row in means}


class TradeTable(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = pathlib.Path(self.tmp.name)

    def tearDown(self):
        self.tmp.cleanup()

    def test_means_errors_and_differences_as_worked_by_hand(self):
        write_run(self.dir / 'U0.07-seed1', 0.07, 1, 5.0, 0.1)
        write_run(self.dir / 'U0.07-seed2', 0.07, 2, 5.2, 0.1)
        write_run(self.dir / 'U0.035-seed1', 0.035, 1, 5.1, 0.3)
        write_run(self.dir / 'U0.035-seed2', 0.035, 2, 5.1, 0.3)
        write_run(self.dir / 'U0.07-alt-seed1', 0.07, 1, 4.5, 0.1)
        write_run(self.dir / 'U0.07-alt-seed2', 0.07, 2, 4.5, 0.1)
        run = trade_table(self.dir)
        self.assertEqual(run.returncode, 0, run.stderr)
        cells = F_cells(run.stdout)
        # the trade's own groups first, largest U_inf first, then the variant; then the differences
        self.assertEqual(list(cells), ['U_inf 0.07', 'U_inf 0.035', 'U_inf 0.07 alt',
                                       '0.07 against 0.035', '0.07 against 0.07 alt'])
        # 0.07: mean 5.1; the seeds' scatter stdev(5.0, 5.2) / sqrt 2 = 0.1414 / 1.414 = 0.100 beats
        # the batch errors' sqrt(0.1^2 + 0.1^2) / 2 = 0.071
        self.assertEqual(cells['U_inf 0.07'], '5.10 +- 0.10')
        # 0.035: no scatter; sqrt(0.3^2 + 0.3^2) / 2 = 0.212
        self.assertEqual(cells['U_inf 0.035'], '5.10 +- 0.21')
        # the variant: no scatter; 0.0707
        self.assertEqual(cells['U_inf 0.07 alt'], '4.50 +- 0.07')
        # 5.1 / 5.1 - 1 = 0, error hypot(0.1/5.1, 0.2121/5.1) = 0.2345 / 5.1 = 4.6 %
        self.assertEqual(cells['0.07 against 0.035'], '+0.0 % +- 4.6 % (0.0)')
        # 5.1 / 4.5 - 1 = +13.3 %, error 1.1333 hypot(0.1/5.1, 0.07071/4.5) = 1.1333 x 0.02513
        # = 2.8 %, and 0.1333 / 0.02848 = 4.7 errors
        self.assertEqual(cells['0.07 against 0.07 alt'], '+13.3 % +- 2.8 % (4.7)')
        # the per-run table names the variant's runs by their group
        self.assertIn('| 0.07 alt, 2 | 4.50 +- 0.10 |', run.stdout)

    def test_a_variant_is_not_a_second_U_inf_of_the_trade(self):
        write_run(self.dir / 'U0.07-seed1', 0.07, 1, 5.0, 0.1)
        write_run(self.dir / 'U0.035-alt-seed1', 0.035, 1, 5.0, 0.1)
        run = trade_table(self.dir)
        self.assertNotEqual(run.returncode, 0)
        self.assertIn('a trade needs runs at two U_inf at least', run.stderr)

    def test_a_variant_with_other_seeds_is_refused(self):
        write_run(self.dir / 'U0.07-seed1', 0.07, 1, 5.0, 0.1)
        write_run(self.dir / 'U0.035-seed1', 0.035, 1, 5.0, 0.1)
        write_run(self.dir / 'U0.07-alt-seed2', 0.07, 2, 5.0, 0.1)
        run = trade_table(self.dir)
        self.assertNotEqual(run.returncode, 0)
        self.assertIn('the seeds differ between groups', run.stderr)

    def test_a_variant_is_compared_at_its_own_U_inf(self):
        # 4.5 at 0.035 alt against the trade's 5.1 at 0.035 (not the reference 0.07): 5.1 / 4.5 - 1
        # = +13.3 %; the error, the ratio's, 1.133 x hypot(0.3 / 5.1, 0.1 / 4.5) = 7.1 % (1.9)
        write_run(self.dir / 'U0.07-seed1', 0.07, 1, 5.0, 0.1)
        write_run(self.dir / 'U0.035-seed1', 0.035, 1, 5.1, 0.3)
        write_run(self.dir / 'U0.035-alt-seed1', 0.035, 1, 4.5, 0.1)
        run = trade_table(self.dir)
        self.assertEqual(run.returncode, 0, run.stderr)
        self.assertIn('| 0.035 against 0.035 alt | +13.3 % +- 7.1 % (1.9) |', run.stdout)

    def test_a_variant_without_the_trades_runs_at_its_U_inf_is_refused(self):
        write_run(self.dir / 'U0.07-seed1', 0.07, 1, 5.0, 0.1)
        write_run(self.dir / 'U0.035-seed1', 0.035, 1, 5.1, 0.3)
        write_run(self.dir / 'U0.05-alt-seed1', 0.05, 1, 4.5, 0.1)
        run = trade_table(self.dir)
        self.assertNotEqual(run.returncode, 0)
        self.assertIn("has no runs of the trade's own at U_inf 0.05", run.stderr)


if __name__ == '__main__':
    unittest.main()
