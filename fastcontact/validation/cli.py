"""``fastcontact bem`` — reference, compare, calibrate (argparse wiring, issue 13).

Hook into the main parser with::

    from .validation.cli import add_bem_commands
    add_bem_commands(sub, comparison_figure)    # in build_parser()
    if a.command == "bem": return getattr(a, "bem_func", None)   # in _dispatch()

Every command has the signature ``cmd(args, out, err) -> exit code`` of the main CLI; bad input
raises ValueError/OSError (reported in one line by the main entry point); a missing optional
extra prints one line and returns 2.
"""
from __future__ import annotations

import argparse
import math

from .._core.vocab import CONVENTIONS

__all__ = ["add_bem_commands", "EXIT_MISSING_EXTRA"]

EXIT_MISSING_EXTRA = 2


def _floats(text):
    try:
        vals = [float(v) for v in text.replace(";", ",").split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a comma-separated list of numbers") \
            from None
    if not vals:
        raise argparse.ArgumentTypeError("the list is empty")
    return vals


def _ints(text):
    try:
        return [int(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a comma-separated list of integers") \
            from None


def add_bem_commands(subparsers, comparison_figure):
    """Add the ``bem`` command group (``reference``, ``compare``, ``calibrate``).

    ``comparison_figure(frame, path)`` draws ``compare --figure`` (handed in by the main CLI:
    figures sit above this layer)."""
    b = subparsers.add_parser("bem", help="BEM reference of a surface; compare and calibrate "
                              "the theories against it (needs fastcontact[bem] for 'reference')")
    kw = {}
    if hasattr(subparsers, "_parser_class"):
        kw["parser_class"] = subparsers._parser_class
    bs = b.add_subparsers(dest="bem_command", metavar="SUBCOMMAND", **kw)

    r = bs.add_parser("reference", help="BEM contact + Reynolds flow on random surfaces of a PSD")
    src = r.add_mutually_exclusive_group(required=True)
    src.add_argument("--psd", help="spectrum file (CSV/Parquet, read_psd)")
    src.add_argument("--hurst", type=float, help="self-affine surface: Hurst exponent H")
    r.add_argument("--convention", choices=tuple(CONVENTIONS),
                   help="C convention of a --psd file that records none")
    r.add_argument("--h-rms", type=float, default=1e-6, help="self-affine h_rms [m]")
    r.add_argument("--q0", type=float, default=None, help="self-affine q0 [1/m] (default 2π/1 mm)")
    r.add_argument("--q1-factor", type=float, default=32.0, help="q1/q0 (self-affine)")
    r.add_argument("--roll-factor", type=float, default=4.0, help="q_roll/q0 (self-affine)")
    r.add_argument("--E-star", type=float, required=True, help="contact modulus E* [Pa]")
    pr = r.add_mutually_exclusive_group(required=True)
    pr.add_argument("--pressures", type=_floats, help="nominal pressures p0 [Pa], comma-separated")
    pr.add_argument("--areas", type=_floats,
                    help="pressures where Persson's A/A0 takes these values, comma-separated")
    r.add_argument("--n", type=int, default=256, help="grid points per side (default 256)")
    r.add_argument("--seeds", type=_ints, default=[0, 1, 2], help="random seeds (default 0,1,2)")
    r.add_argument("--eta", type=float, default=1e-3, help="viscosity [Pa s] (default 1e-3)")
    r.add_argument("--no-progress", action="store_true", help="no progress bar")
    r.add_argument("-o", "--output", required=True, help="reference file (.parquet)")
    r.set_defaults(bem_func=_cmd_reference)

    c = bs.add_parser("compare", help="every theory beside a reference: errors of A, ū, σ_eff, "
                      "flow stop and squeeze-out time")
    c.add_argument("reference", help="reference file written by 'fastcontact bem reference'")
    c.add_argument("--E-star", type=float, default=None, help="[Pa] (default: the reference's)")
    c.add_argument("--calibration", help="calibration file (.toml or .json) to compare as well")
    c.add_argument("-o", "--output", required=True, help="comparison table (.csv or .parquet)")
    c.add_argument("--figure", help="write a figure (PNG/PDF)")
    c.set_defaults(bem_func=_cmd_compare, bem_figure=comparison_figure)

    k = bs.add_parser("calibrate", help="fit γ, α_cj, a_perc and the Bruggeman threshold jointly")
    k.add_argument("reference", help="reference file (.parquet from 'bem reference', or .csv)")
    k.add_argument("--E-star", type=float, default=None, help="[Pa] (default: the reference's)")
    k.add_argument("--psd", help="spectrum file (default: the PSD in the reference's provenance)")
    k.add_argument("-o", "--output", required=True, help="calibration file (.toml or .json)")
    k.set_defaults(bem_func=_cmd_calibrate)
    return b


def _e_star(a, ref):
    e = a.E_star if a.E_star is not None else ref.attrs.get("E_star")
    if e is None:
        raise ValueError("--E-star is missing: the reference records no E_star [Pa]")
    return float(e)


def _read_psd(path, convention=None):
    """The spectrum in the file ``path`` (:func:`fastcontact.read_psd`)."""
    from .. import read_psd
    return read_psd(path, convention)


def _read_calibration(path):
    """The :class:`Calibration` in the file ``path`` (.json, else TOML), or None without one."""
    if not path:
        return None
    from .calibration import Calibration
    return (Calibration.from_json if path.endswith(".json") else Calibration.from_toml)(path)


def _write_table(df, path):
    """Write ``df`` to ``path``: Parquet if the name ends in .parquet, else CSV (no index)."""
    if path.lower().endswith(".parquet"):
        df.to_parquet(path)
    else:
        df.to_csv(path, index=False)


def _cmd_reference(a, out, err):
    from .. import contact
    from ..psd import SelfAffinePSD
    from .bem import bem_reference
    from .compare import write_reference

    if a.psd:
        psd = _read_psd(a.psd, a.convention)
    else:
        q0 = a.q0 if a.q0 is not None else 2 * math.pi / 1e-3
        psd = SelfAffinePSD(h_rms=a.h_rms, hurst=a.hurst, q0=q0, q1=a.q1_factor * q0,
                            q_roll=a.roll_factor * q0)
    p = a.pressures if a.pressures else contact.percolation_pressure(psd, a.E_star, a.areas)
    try:
        df = bem_reference(psd, a.E_star, p, n=a.n, seeds=a.seeds, eta=a.eta,
                           progress=not a.no_progress)
    except ImportError as exc:
        print(f"fastcontact: error: {exc}", file=err)
        return EXIT_MISSING_EXTRA
    write_reference(df, a.output)
    stop = df.attrs["flow_stop_pressure"]
    print(f"wrote {a.output}: {len(df)} pressures, n = {a.n}, {len(a.seeds)} seeds, "
          f"flow stops at p0 = {stop:.4g} Pa; {len(df.attrs['warnings'])} warning(s)", file=out)
    for w in df.attrs["warnings"]:
        print(f"warning: {w}", file=out)
    return 0


def _cmd_compare(a, out, err):
    from .compare import compare_theories, read_reference

    ref = read_reference(a.reference)
    cal = _read_calibration(a.calibration)
    cmp = compare_theories(None, _e_star(a, ref), ref, calibration=cal)
    _write_table(cmp, a.output)
    for label, s in cmp.attrs["flow_stop"].items():
        print(f"{label:24s} flow stop theory/BEM = {s['ratio']:.3g}", file=out)
    if a.figure:
        try:
            a.bem_figure(cmp, a.figure)
        except ImportError as exc:
            print(f"note: {exc}", file=err)
    print(f"wrote {a.output}", file=out)
    return 0


def _cmd_calibrate(a, out, err):
    from .calibration import calibrate
    from .compare import read_reference

    ref = read_reference(a.reference)
    psd = _read_psd(a.psd) if a.psd else None
    cal = calibrate(psd, _e_star(a, ref), ref)
    if a.output.lower().endswith(".json"):
        cal.to_json(a.output)
    else:
        cal.to_toml(a.output)
    print(f"gamma = {cal.gamma:.4g}, alpha_cj = {cal.alpha_cj:.4g}, a_perc = {cal.a_perc:.4g}, "
          f"emt_threshold = {cal.emt_threshold:.4g} (fitted: {', '.join(cal.fitted)})", file=out)
    print(f"wrote {a.output}", file=out)
    return 0
