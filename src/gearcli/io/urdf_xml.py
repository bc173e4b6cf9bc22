"""Safe reading of URDF (XML) files, shared by the URDF modules.

* the file is read whole within :data:`~gearcli.io.limits.MAX_BYTES`;
* internal entities (``<!DOCTYPE robot [<!ENTITY red "50">]>``) are expanded; external
  ones (``SYSTEM``/``PUBLIC``) are refused with their line, and nothing besides the file
  itself is ever read: no external DTD (``load_dtd=False``), no network, no XInclude (never
  processed), no mesh file (yourdfpy is given the parsed tree, with meshes off);
* libxml2's own limits apply (nesting depth 256, entity amplification);
* numbers are finite and within :data:`~gearcli.model.validate.MAX_ABS`;
* yourdfpy runs with its log records and prints silenced.
"""
from __future__ import annotations

import contextlib
import io
import logging
import re

import numpy as np
from lxml import etree

from ..errors import Issue, MechanismError
from ..model.validate import MAX_ABS, number_problem

NS = "https://gearcli.dev/urdf/1"
"""XML namespace of gearcli's URDF extension elements (prefix ``gearcli``)."""


def q(tag: str) -> str:
    """Qualified name of a gearcli extension element or attribute."""
    return f"{{{NS}}}{tag}"


def placeholders(limit_el) -> set[str]:
    """The attributes of a ``<limit>`` element that ``gearcli export`` wrote only because URDF
    requires them (``gearcli:placeholder="effort velocity"``: a joint with position limits
    but no effort/velocity ratings; ``"lower upper effort velocity"``: a prismatic joint
    without any limits); gearcli ignores them on reading."""
    return set((limit_el.get(q("placeholder")) or "").split()) if limit_el is not None else set()


def _fromstring(data: bytes, file: str, resolve):
    parser = etree.XMLParser(remove_comments=True, resolve_entities=resolve, no_network=True,
                             load_dtd=False, dtd_validation=False, huge_tree=False)
    try:
        return etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        line = exc.lineno if getattr(exc, "lineno", None) else None
        msg = str(exc.msg if getattr(exc, "msg", None) else exc)
        msg = msg.split(", line ")[0]
        raise MechanismError([Issue(file, "", line, f"malformed XML: {msg}")]) from None


def _declaration_line(data: bytes, name: str) -> int | None:
    m = re.search(rb"<!ENTITY\s+(?:%\s+)?" + re.escape(name.encode()) + rb"\s", data)
    return data.count(b"\n", 0, m.start()) + 1 if m else None


def parse_xml(data: bytes, file: str):
    """Root element of the URDF ``data`` with internal entities expanded; raises
    :class:`~gearcli.errors.MechanismError` (one located line) for malformed XML, an
    external entity, or an entity reference declared nowhere in the file."""
    root = _fromstring(data, file, False)
    dtd = root.getroottree().docinfo.internalDTD
    if dtd is not None:
        entities = list(dtd.iterentities())
        for ent in entities:
            if ent.system_url is not None or ent.content is None:
                where = f" (SYSTEM \"{ent.system_url}\")" if ent.system_url else ""
                raise MechanismError([Issue(file, "DOCTYPE", _declaration_line(data, ent.name),
                                            f"external entity '{ent.name}'{where} is refused: gearcli reads "
                                            "nothing but the file itself")])
        if entities:
            root = _fromstring(data, file, "internal")
    for ref in root.iter(etree.Entity):
        raise MechanismError([Issue(file, "", ref.sourceline or None, f"entity reference {ref.text} is not "
                                    "declared in the file (external DTDs and entities are not read)")])
    return root


# A number as XML Schema's xs:double writes it (ASCII digits, no digit separators; inf and nan
# are read, for the callers to refuse as not finite): float() would also take "0_05" (as 5).
_DECIMAL = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|[+-]?(?:inf|infinity|nan)", re.I)


def decimal_numbers(text: str) -> list[float]:
    """The whitespace-separated numbers of ``text`` (decimal, inf, nan); ValueError for any other token."""
    words = text.split()
    if not all(_DECIMAL.fullmatch(w) for w in words):
        raise ValueError(text)
    return [float(w) for w in words]


def floats(text: str | None, n: int | None = None) -> np.ndarray | None:
    """Whitespace-separated decimal numbers, or None if malformed (``0_05``, ``0,5``), the
    wrong count, not finite or beyond :data:`~gearcli.model.validate.MAX_ABS`
    (:func:`range_problem` tells)."""
    if text is None:
        return None
    try:
        v = np.array(decimal_numbers(text), float)
    except ValueError:
        return None
    if (n is not None and v.size != n) or not np.all(np.isfinite(v)) or np.any(np.abs(v) > MAX_ABS):
        return None
    return v


def range_problem(text: str | None) -> str | None:
    """Why a finite number in ``text`` is out of range, or None."""
    try:
        values = decimal_numbers(text or "")
    except ValueError:
        return None
    return next((number_problem(v) for v in values if np.isfinite(v) and number_problem(v)), None)


@contextlib.contextmanager
def quiet_yourdfpy():
    """Silence yourdfpy while it runs: its log records (``Using different parsing
    approach.``) and anything it prints would otherwise reach the user's terminal."""
    loggers = [logging.getLogger(n) for n in ("yourdfpy", "yourdfpy.urdf", "trimesh")]
    saved = [(lg, lg.disabled) for lg in loggers]
    for lg in loggers:
        lg.disabled = True
    sink = io.StringIO()
    try:
        with contextlib.redirect_stdout(sink), contextlib.redirect_stderr(sink):
            yield
    finally:
        for lg, was in saved:
            lg.disabled = was


def load_yourdfpy(root):
    """A yourdfpy URDF of the parsed ``root`` (entities expanded, no DOCTYPE); meshes,
    scene graphs and files other than this one are never loaded."""
    import yourdfpy  # noqa: PLC0415  (slow import, only for URDF)

    data = etree.tostring(root)
    with quiet_yourdfpy():
        return yourdfpy.URDF.load(io.BytesIO(data), build_scene_graph=False, load_meshes=False,
                                  build_collision_scene_graph=False, load_collision_meshes=False)
