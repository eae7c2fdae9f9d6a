"""Compare two chain_dump outputs: report the largest relative difference per record kind."""

import sys


def main(a_path: str, b_path: str, tol: float = 1e-12) -> int:
    with open(a_path) as fa, open(b_path) as fb:
        a_lines, b_lines = fa.read().splitlines(), fb.read().splitlines()
    if len(a_lines) != len(b_lines):
        print(f"line counts differ: {len(a_lines)} vs {len(b_lines)}")
        return 1
    worst, identical, bad = {}, True, 0
    for la, lb in zip(a_lines, b_lines):
        ta, tb = la.split(), lb.split()
        if ta[0] != tb[0] or len(ta) != len(tb):
            print(f"structure differs:\n  {la[:120]}\n  {lb[:120]}")
            return 1
        if la != lb:
            identical = False
        for x, y in zip(ta[1:], tb[1:]):
            try:
                fx, fy = float(x), float(y)
            except ValueError:
                continue
            d = abs(fx - fy) / max(1.0, abs(fx), abs(fy))
            worst[ta[0]] = max(worst.get(ta[0], 0.0), d)
            bad += d > tol
    print("bit-identical" if identical else "not bit-identical")
    for k, v in sorted(worst.items()):
        print(f"  {k:6s} max rel diff {v:.3g}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
