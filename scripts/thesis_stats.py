"""Small statistics for comparing counts of correct trials (standard library only).

wilson(k, n)            the 95% Wilson score interval of k of n
fisher_exact(a, n, b, m) two-sided Fisher's exact test of a of n against b of m
mcnemar_exact(b, c)     two-sided exact McNemar test of paired trials (b, c: the discordant pairs)
chi2_homogeneity(ks, n) chi-square test that several counts k of n share one rate (statistic, df, p)
chi2_sf(x, df)          the chi-square distribution's upper tail
kendall_tau(x, y)       Kendall's tau-b of two equally long sequences (None when undefined)
count_of(value, n)      the count k = round(value * n) behind a printed fraction
printable_as_count(value, n)  whether a printed percentage can be some k/n
fitting_n(values, n)    the largest n' <= n at which all of a row's percentages are k/n'

Used by scripts/thesis_report/ and scripts/thesis_verdicts.py.
"""
import math

Z95 = 1.959963984540054
FISHER_REL_TOL = 1e-7  # as scipy.stats.fisher_exact: tables as probable as the observed one, within this


def wilson(k, n, z=Z95):
    """The Wilson score interval of k successes in n trials, as (lo, hi);
    (0, 1) for n = 0 (scripts/plot.py and eval/stats.h compute the same)."""
    if n <= 0:
        return 0.0, 1.0
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    # exactly 0 / 1 at the ends (c - h and c + h are 0 and 1 there but for rounding)
    return (0.0 if k == 0 else max(0.0, c - h)), (1.0 if k == n else min(1.0, c + h))


def fisher_exact(a, n, b, m):
    """Two-sided p of Fisher's exact test of the 2x2 table (a, n - a; b, m - b):
    the sum of the hypergeometric probabilities (margins fixed) of every table
    at most as probable as the observed one, within a relative tolerance."""
    if not (0 <= a <= n and 0 <= b <= m):
        raise ValueError("counts out of range: %d of %d, %d of %d" % (a, n, b, m))
    k, total = a + b, n + m
    lo, hi = max(0, k - m), min(k, n)
    # integer weights comb(n, x) comb(m, k - x); their sum is comb(n + m, k)
    weights = [math.comb(n, x) * math.comb(m, k - x) for x in range(lo, hi + 1)]
    observed = weights[a - lo]
    p = sum(w for w in weights if w <= observed * (1 + FISHER_REL_TOL)) / math.comb(total, k)
    return min(1.0, p)


def mcnemar_exact(b, c):
    """Two-sided p of McNemar's exact test for paired trials: b pairs correct
    in the first run only, c in the second only. Under no difference each
    discordant pair falls either way with probability 1/2, so the p is twice
    the binomial tail of min(b, c) in b + c draws (at most 1); 1 when no pair
    differs."""
    if b < 0 or c < 0:
        raise ValueError("negative counts: %d, %d" % (b, c))
    n = b + c
    tail = sum(math.comb(n, i) for i in range(min(b, c) + 1))
    return min(1.0, 2 * tail / 2 ** n)


def chi2_sf(x, df):
    """P(X >= x) for X chi-square with df degrees of freedom: the regularized
    upper incomplete gamma Q(df / 2, x / 2), by its series below a + 1 and
    its continued fraction (modified Lentz) above."""
    if df <= 0:
        raise ValueError("df must be positive: %r" % df)
    if x <= 0:
        return 1.0
    a, z = df / 2.0, x / 2.0
    log_front = a * math.log(z) - z - math.lgamma(a)
    if z < a + 1:  # P by the series, Q = 1 - P
        term = total = 1.0 / a
        k = a
        while abs(term) > abs(total) * 1e-15:
            k += 1
            term *= z / k
            total += term
        return max(0.0, 1.0 - total * math.exp(log_front))
    tiny = 1e-300
    b = z + 1 - a
    c, d = 1 / tiny, 1 / b
    h = d
    for i in range(1, 10000):
        an = -i * (i - a)
        b += 2
        d = an * d + b
        d = tiny if abs(d) < tiny else d
        c = b + an / c
        c = tiny if abs(c) < tiny else c
        d = 1 / d
        delta = d * c
        h *= delta
        if abs(delta - 1) < 1e-15:
            break
    return min(1.0, math.exp(log_front) * h)


def chi2_homogeneity(ks, n):
    """Pearson's chi-square test that counts ks, each k of n trials, share one
    rate (a len(ks) x 2 table): (statistic, df, p). p is 1 when every count is
    the same (0 of n or n of n included: no spread to test). The chi-square
    approximation is rough where expected counts fall below 5."""
    if len(ks) < 2 or n <= 0 or any(not 0 <= k <= n for k in ks):
        raise ValueError("need two or more counts, each of 0..%d: %r" % (n, ks))
    df = len(ks) - 1
    total = sum(ks)
    if all(k == ks[0] for k in ks):
        return 0.0, df, 1.0
    p = total / (n * len(ks))
    e1, e0 = n * p, n * (1 - p)
    stat = sum((k - e1) ** 2 / e1 + ((n - k) - e0) ** 2 / e0 for k in ks)
    return stat, df, chi2_sf(stat, df)


def _sign(v, tol=1e-12):
    return 0 if abs(v) <= tol else (1 if v > 0 else -1)


def kendall_tau(x, y):
    """Kendall's tau-b of x and y (pairs tied in one of them count in its
    denominator only); None when every pair is tied in x or in y."""
    if len(x) != len(y):
        raise ValueError("kendall_tau: sequences of different lengths")
    concordant = discordant = untied_x = untied_y = 0
    for i in range(len(x)):
        for j in range(i + 1, len(x)):
            sx, sy = _sign(x[i] - x[j]), _sign(y[i] - y[j])
            untied_x += sx != 0
            untied_y += sy != 0
            if sx and sy:
                concordant += sx == sy
                discordant += sx != sy
    if not untied_x or not untied_y:
        return None
    return (concordant - discordant) / math.sqrt(untied_x * untied_y)


def count_of(value, n):
    """The count behind a fraction printed for n trials: round(value * n), halves up."""
    return int(math.floor(value * n + 0.5 + 1e-9))


def printable_as_count(value, n):
    """Whether the percentage `value` (as printed, whole percent) is k/n for
    some whole k, rounded to a whole percent."""
    pct = round(100 * value)
    return any(abs(100 * k / n - pct) <= 0.5 + 1e-9 for k in range(n + 1))


def fitting_n(values, n):
    """The largest m from n down to n // 2 at which every printed fraction of
    `values` is some k/m (whole percent), or None."""
    return next((m for m in range(n, max(1, n // 2) - 1, -1) if all(printable_as_count(v, m) for v in values)),
                None)


def within_points(a, b, points):
    """|a - b| at most `points` percentage points (fractions a, b)."""
    return abs(a - b) <= points / 100 + 1e-9
