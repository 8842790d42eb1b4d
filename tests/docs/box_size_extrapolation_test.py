#!/usr/bin/env python3
"""scripts/box-size-extrapolation.py against a case worked by hand: three boxes whose weighted
least-squares line, its errors, chi^2 and residuals are derived below in exact fractions, the
--error-scale option, --check, and the input it must refuse.
Run: python3 tests/docs/box_size_extrapolation_test.py (from the repository root)."""
import json, pathlib, subprocess, sys, tempfile, unittest

SCRIPT = pathlib.Path(__file__).resolve().parents[2] / 'scripts' / 'box-size-extrapolation.py'

# N = 8, 27, 64: x = N^(-1/3) = 1/2, 1/3, 1/4; y = 0.80, 0.87, 0.90, each +- 0.01 (equal weights,
# so the ordinary least-squares formulas apply).
#   mean x = 13/36; deviations 5/36, -1/36, -4/36; S_xx = 42/1296 = 7/216
#   mean y = 257/300; deviations -17/300, 4/300, 13/300
#   S_xy = (5 (-17) + (-1) 4 + (-4) 13) / 10800 = -141/10800
#   slope m = S_xy / S_xx = -141/350 = -0.402857, so b = 0.403
#   y_inf = mean y - m mean x = 257/300 + (141/350)(13/36) = 12627/12600 = 1.002143
#   fit: 0.800714, 0.867857, 0.901429; residuals / 0.01 = -1/14, +3/14, -2/14 = -0.07, +0.21, -0.14
#   chi^2 = (1 + 9 + 4) / 196 = 1/14 = 0.07 over 3 - 2 = 1 degree of freedom
#   error of y_inf: 0.01 sqrt(1/3 + (13/36)^2 / (7/216)) = 0.01 sqrt(183/42) = 0.020874
#   error of b: 0.01 sqrt(216/7) = 0.055549
BOXES = [(2, [12, 6, 6], 8, 0.80), (3, [18, 9, 9], 27, 0.87), (4, [24, 12, 12], 64, 0.90)]

EXPECTED = [
    '| 2 | 12x6x6 | 8 | 0.500 | 0.8000 | 0.0100 | 0.8007 | -0.07 | test |',
    '| 3 | 18x9x9 | 27 | 0.333 | 0.8700 | 0.0100 | 0.8679 | +0.21 | test |',
    '| 4 | 24x12x12 | 64 | 0.250 | 0.9000 | 0.0100 | 0.9014 | -0.14 | test |',
    '| N -> infinity | | | 0 | | | 1.0021 +- 0.0209 | | |',
]
SLOPE = ('Slope b = 0.403 +- 0.056 (U_over_Uinf = y_inf - b N^(-1/3)); chi^2 = 0.07 over 1 degree '
         'of freedom; errors are the runs\' batch-means errors times 1.')


def result(L, cells, N, y, error=0.01):
    return {'flocsim_version': 'test', 'case': {'L_over_a': L},
            'derived': {'sphere_count': N, 'box_cells': cells},
            'observables': {'U_over_Uinf': {'mean': y, 'error': error}}}


class BoxSizeExtrapolation(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.files = []
        for L, cells, N, y in BOXES:
            path = pathlib.Path(self.dir.name) / f'L{L}.json'
            path.write_text(json.dumps(result(L, cells, N, y)))
            self.files.append(str(path))

    def tearDown(self):
        self.dir.cleanup()

    def run_script(self, *args):
        return subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True, text=True)

    def test_hand_worked_fit(self):
        out = self.run_script(*reversed(self.files))  # sorted by N whatever the order given
        self.assertEqual(out.returncode, 0, out.stderr)
        lines = out.stdout.splitlines()
        self.assertEqual(lines[2:6], EXPECTED)
        self.assertEqual(lines[7], SLOPE)

    def test_error_scale_widens_errors_not_the_line(self):
        # errors x 2: the same line, y_inf's error 0.0417, residuals halved, chi^2 / 4 = 1/56
        out = self.run_script('--error-scale', '2', *self.files)
        self.assertEqual(out.returncode, 0, out.stderr)
        lines = out.stdout.splitlines()
        self.assertEqual(lines[2], '| 2 | 12x6x6 | 8 | 0.500 | 0.8000 | 0.0200 | 0.8007 | -0.04 | test |')
        self.assertEqual(lines[5], '| N -> infinity | | | 0 | | | 1.0021 +- 0.0417 | | |')
        self.assertIn('b = 0.403 +- 0.111', lines[7])
        self.assertIn('chi^2 = 0.02 over 1 degree', lines[7])

    def test_two_boxes_give_the_exact_line(self):
        # (1/2, 0.80) and (1/4, 0.90): slope -0.4, y_inf = 0.80 + 0.4 / 2 = 1.0
        out = self.run_script(self.files[0], self.files[2])
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn('| N -> infinity | | | 0 | | | 1.0000 +-', out.stdout)
        self.assertIn('b = 0.400', out.stdout)
        self.assertIn('two boxes: the line is exact', out.stdout)

    def test_check_finds_the_table_and_a_changed_row(self):
        doc = pathlib.Path(self.dir.name) / 'doc.md'
        table = self.run_script(*self.files).stdout
        doc.write_text('# page\n\n' + table + '\nmore text\n')
        self.assertEqual(self.run_script('--check', str(doc), *self.files).returncode, 0)
        doc.write_text('# page\n\n' + table.replace('1.0021', '1.0022') + '\n')
        out = self.run_script('--check', str(doc), *self.files)
        self.assertEqual(out.returncode, 1)
        self.assertIn('does not hold this table', out.stderr)

    def test_refusals(self):
        one_size = self.run_script(self.files[0], self.files[0])
        self.assertEqual(one_size.returncode, 1)
        self.assertIn('need at least two box sizes', one_size.stderr)
        zero = pathlib.Path(self.dir.name) / 'zero.json'
        zero.write_text(json.dumps(result(5, [30, 15, 15], 125, 0.9, error=0)))
        out = self.run_script(self.files[0], str(zero))
        self.assertEqual(out.returncode, 1)
        self.assertIn('no positive error', out.stderr)
        out = self.run_script('--quantity', 'F', *self.files)
        self.assertEqual(out.returncode, 1)
        self.assertIn("with F", out.stderr)
        out = self.run_script('--error-scale', '0', *self.files)
        self.assertEqual(out.returncode, 1)
        self.assertIn('--error-scale 0.0: must be a positive number', out.stderr)


if __name__ == '__main__':
    unittest.main()
