"""The package's vocabulary, defined once: theory and convention names, the Parquet metadata
key, the literature with DOIs, and the one formatter of numbered result-column names."""
from __future__ import annotations

__all__ = ["THEORIES", "THEORY_LABELS", "DEFAULT_THEORY", "CONVENTIONS", "METADATA_KEY",
           "REFERENCES", "reference_list", "column_name"]

#: flow-conductivity theories, in canonical order
THEORIES = ("average", "critical_junction", "emt")
#: human-readable names of the theories
THEORY_LABELS = {"average": "average separation", "critical_junction": "critical junction",
                 "emt": "Bruggeman effective medium"}
#: the theory used where a call does not name one (squeeze-out and seals alike)
DEFAULT_THEORY = "critical_junction"

#: PSD conventions and the factor that turns a spectrum given in that convention into the
#: Persson convention (h_rms² = 2π∫q C dq); SurfaceTopography / contact.engineering use
#: C_ST = (2π)² C_Persson
CONVENTIONS = {"persson": 1.0, "surface_topography": 1.0 / (2.0 * 3.141592653589793) ** 2}

#: key of fastcontact's JSON block in Parquet key-value metadata
METADATA_KEY = b"fastcontact"

#: literature the engines implement: key -> (citation, identifier); the identifier is a DOI
#: ("10.…") or, where only the preprint could be confirmed, an arXiv number ("arXiv:…")
REFERENCES = {
    "lorenz_persson_2010_squeeze": (
        "B. Lorenz and B.N.J. Persson, Time-dependent fluid squeeze-out between solids with "
        "rough surfaces, Eur. Phys. J. E 32, 281 (2010)", "arXiv:1004.1037"),
    "persson_2001": (
        "B.N.J. Persson, Theory of rubber friction and contact mechanics, "
        "J. Chem. Phys. 115, 3840 (2001)", "10.1063/1.1388626"),
    "yang_persson_2008": (
        "C. Yang and B.N.J. Persson, Contact mechanics: contact area and interfacial separation "
        "from small contact to full contact, J. Phys.: Condens. Matter 20, 215214 (2008)",
        "10.1088/0953-8984/20/21/215214"),
    "lorenz_persson_2010_seals": (
        "B. Lorenz and B.N.J. Persson, Leak rate of seals: effective-medium theory and "
        "comparison with experiment, Eur. Phys. J. E 31, 159 (2010)", "arXiv:0911.3019"),
    "almqvist_2011": (
        "A. Almqvist, C. Campañá, N. Prodanov and B.N.J. Persson, Interfacial separation between "
        "elastic solids with randomly rough surfaces, J. Mech. Phys. Solids 59, 2355 (2011)",
        "10.1016/j.jmps.2011.08.004"),
    "patir_cheng_1978": (
        "N. Patir and H.S. Cheng, An average flow model for determining effects of "
        "three-dimensional roughness on partial hydrodynamic lubrication, "
        "J. Lubr. Technol. 100, 12 (1978)", "10.1115/1.3453103"),
}


def reference_list(keys=None) -> list[str]:
    """Citations with DOIs (all, or those named by ``keys``), as one string each."""
    keys = REFERENCES if keys is None else keys
    out = []
    for k in keys:
        citation, ident = REFERENCES[k]
        out.append(f"{citation}, {ident}" if ident.startswith("arXiv:") else f"{citation}, doi:{ident}")
    return out


def column_name(prefix: str, value) -> str:
    """The result-column name for a numbered output, e.g. ``column_name("t_ratio", 1.01)``
    → ``"t_ratio_1.01"``.

    Six significant digits (``%g``) where they give the value back exactly, otherwise the
    shortest representation that does (``repr``): names are exact and two different values
    never share a name.
    """
    v = float(value)
    short = f"{v:g}"
    return f"{prefix}_{short if float(short) == v else repr(v)}"
