#!/usr/bin/env python3
"""Independent reference for test_device_gen_fitpack (SmoothingReference).

Computes, with exact rational arithmetic (sympy) and 40-digit root finding
(mpmath), the cubic smoothing spline of FITPACK's curfit for a small data set
where the knot selection can be checked by hand:

  m = 11 points, x = 0..10. The least-squares cubic has fp0 > s, so one knot
  is added at the middle data point x(6) = 5 (fpknot: nrdata = m-2 = 9,
  ihalf = 9/2+1 = 5, x(1+5)); the least-squares spline on that knot has
  fp1 < s, so no more knots are added and the smoothing spline is the one on
  t = [0,0,0,0,5,10,10,10,10] that minimises the squared jump of s''' at 5
  subject to fp = s (Dierckx 1993, 5.2). This script does not use the C++
  code nor FITPACK's Givens/rational-interpolation machinery: it builds the
  B-splines symbolically, solves the penalised normal equations
  (A^T W^2 A + lam J^T J) c = A^T W^2 y exactly for a symbolic lam and finds
  lam with fp(lam) = s. Run: python3 smoothing_spline_reference.py
"""
import sympy as sp
import mpmath as mp

mp.mp.dps = 40
X = sp.symbols('X')
xs = [sp.Integer(i) for i in range(11)]
ys = [sp.Rational(v) for v in ['0', '0.1', '0.3', '0.2', '0.5', '1.2', '0.6', '0.4', '0.5', '0.3', '0.2']]
ws = [sp.Rational(v) for v in ['1', '1', '1', '2', '1', '1', '1', '0.5', '1', '1', '1']]
S = sp.Rational(45, 100)


def basis(knots):
    return sp.bspline_basis_set(3, knots, X)


def design(knots):
    B = basis(knots)
    return sp.Matrix([[b.subs(X, x) for b in B] for x in xs]), B


def lsq_residual(knots):
    A, _ = design(knots)
    W = sp.diag(*ws)
    c = (A.T * W * W * A).LUsolve(A.T * W * W * sp.Matrix(ys))
    r = W * (sp.Matrix(ys) - A * c)
    return (r.T * r)[0]


fp0 = lsq_residual([0, 0, 0, 0, 10, 10, 10, 10])
fp1 = lsq_residual([0, 0, 0, 0, 5, 10, 10, 10, 10])
print('fp0 (least-squares cubic) =', sp.N(fp0, 20), ' fp1 (one knot at 5) =', sp.N(fp1, 20), ' s =', S)
assert fp0 > S > fp1

knots = [0, 0, 0, 0, 5, 10, 10, 10, 10]
A, B = design(knots)
# jump of the third derivative of each B-spline at x = 5
J = sp.Matrix([[sp.diff(b, X, 3).subs(X, sp.Rational(51, 10)) - sp.diff(b, X, 3).subs(X, sp.Rational(49, 10)) for b in B]])
W = sp.diag(*ws)
# exact matrices, then 40-digit arithmetic in lambda
AtA = mp.matrix((A.T * W * W * A).tolist())
JtJ = mp.matrix((J.T * J).tolist())
rhs = mp.matrix((A.T * W * W * sp.Matrix(ys)).tolist())
Am = mp.matrix(A.tolist())
wv = [mp.mpf(sp.N(wi, 40)) for wi in ws]
yv = [mp.mpf(sp.N(yi, 40)) for yi in ys]


def coefficients(lam):
    return mp.lu_solve(AtA + lam * JtJ, rhs)


def fp(lam):
    c = coefficients(lam)
    return mp.fsum((wv[i] * (yv[i] - mp.fsum(Am[i, j] * c[j] for j in range(Am.cols)))) ** 2 for i in range(Am.rows))


# fp grows monotonically with lam from fp1 (lam = 0) to fp0 (lam -> inf); bisect in log(lam)
def lam_for(target):
    lo, hi = mp.mpf(-30), mp.mpf(30)
    for _ in range(200):
        mid = (lo + hi) / 2
        if fp(mp.e ** mid) > target:
            hi = mid
        else:
            lo = mid
    return mp.e ** ((lo + hi) / 2)


s40 = mp.mpf(sp.N(S, 40))
lam = lam_for(s40)
coeffs = coefficients(lam)
print('lambda =', mp.nstr(lam, 20), ' fp =', mp.nstr(fp(lam), 20))
print('coefficients =', ', '.join(mp.nstr(ci, 17) for ci in coeffs))
# FITPACK stops within |fp - s| < 0.001 s: the test compares at its own fp
# using the first-order change of the coefficients with fp.
d = mp.mpf('1e-8')
cp, cm = coefficients(lam_for(s40 + d)), coefficients(lam_for(s40 - d))
print('dc/dfp =', ', '.join(mp.nstr((cp[j] - cm[j]) / (2 * d), 17) for j in range(len(coeffs))))
for xv in [sp.Rational(5, 2), sp.Rational(29, 4)]:
    val = mp.fsum(coeffs[j] * mp.mpf(sp.N(B[j].subs(X, xv), 40)) for j in range(len(B)))
    print('s(%s) =' % xv, mp.nstr(val, 17))
