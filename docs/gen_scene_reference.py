"""The scene reference (docs/reference/scene.md), generated from the schema.

    python docs/gen_scene_reference.py [OUT.md]      # default: print to stdout

Everything here is read from the code, so the page cannot drift from it:

* the tables and keys: the fields of the frozen dataclasses that
  :func:`mpipd.input.schema.build` fills, walked from
  :class:`mpipd.input.scene.Scene`;
* the kinds of a tagged table (``model``, ``kind``, ``distribution``): the
  registries (:class:`mpipd.input.schema.Registry`) the fields name;
* types and defaults: the annotations and the dataclass defaults;
* the text: each class's docstring (and its dataclass bases'), the comment on
  a field's line, and the rules of its ``check`` method (``positive``,
  ``non_negative`` and the messages of ``fail``);
* allowed values: the constants the checks test against (:data:`ALLOWED`).

Units are the one thing the code does not state per key: :data:`UNITS` gives
them, and tests/test_docs.py fails when a numeric key has none (or an entry
names a key that no longer exists).  The mkdocs build runs :func:`render`
through docs/hooks.py; ``make docs`` builds the site.
"""
from __future__ import annotations

import ast
import dataclasses
import importlib
import inspect
import io
import re
import sys
import textwrap
import tokenize
import types
import typing
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from mpipd.input import scene as scene_module  # noqa: E402
from mpipd.input.schema import Registry  # noqa: E402

#: the order of the top-level tables on the page (a table not named here follows them)
TOP_ORDER = ("scene", "time", "materials", "parts", "solver", "initial", "boundaries", "loads",
             "probes", "joints", "output")

#: units by key name, for names that mean the same wherever they occur
UNITS_BY_NAME = {
    "density": "kg/m³", "bulk_modulus": "Pa", "shear_modulus": "Pa",
    "lo": "m", "hi": "m", "center": "m", "radius": "m", "inner_radius": "m", "z": "m",
    "start": "m", "end": "m", "point": "m", "position": "m", "dx": "m",
    "velocity": "m/s", "seed": "—",
}

#: units by (class, key): the rest.  "1": a dimensionless number; "—": an integer
#: label or count without a unit
UNITS = {
    ("Time", "dt"): "s", ("Time", "steps"): "steps", ("Time", "t_end"): "s",
    ("Multirate", "max_ratio"): "1", ("Multirate", "safety"): "1",
    ("Multirate", "fracture_class"): "—", ("Multirate", "fracture_window"): "coarse steps",
    ("Part", "horizon_factor"): "× dx", ("Part", "jitter"): "× dx", ("Part", "jitter_seed"): "—",
    ("Grade", "dx_outer"): "m", ("Grade", "zones"): "—",
    ("Band", "width"): "m", ("Band", "horizon_factor"): "× dx",
    ("Initiation", "time"): "s", ("Initiation", "direction"): "1",
    ("Solver", "hourglass"): "1", ("Solver", "progress_every"): "steps",
    ("Solver", "damping"): "1/s", ("Solver", "max_imbalance"): "× ledger scale",
    ("Viscosity", "cq"): "1", ("Viscosity", "cl"): "1",
    ("Output", "every"): "steps", ("Output", "checkpoint_every"): "steps",
    ("Output", "peak_center"): "m",
    ("Joint", "normal"): "1", ("Joint", "spacing"): "m", ("Joint", "persistence"): "1",
    ("Joint", "patch"): "m",
    ("J2", "yield_stress"): "Pa",
    ("JH2", "K2"): "Pa", ("JH2", "K3"): "Pa", ("JH2", "HEL"): "Pa", ("JH2", "p_HEL"): "Pa",
    ("JH2", "A"): "1", ("JH2", "N"): "1", ("JH2", "B"): "1", ("JH2", "M"): "1",
    ("JH2", "C"): "1", ("JH2", "T"): "Pa", ("JH2", "beta"): "1", ("JH2", "D1"): "1",
    ("JH2", "D2"): "1", ("JH2", "rate_norm"): "1/s",
    ("JWL", "A"): "Pa", ("JWL", "B"): "Pa", ("JWL", "R1"): "1", ("JWL", "R2"): "1",
    ("JWL", "omega"): "1", ("JWL", "e0"): "J/m³", ("JWL", "vod"): "m/s",
    ("Explosive", "initiation_z"): "m", ("Explosive", "direction"): "1",
    ("Explosive", "burn_ramp"): "× dx", ("Explosive", "damping"): "1/s",
    ("Explosive", "pressure_factor"): "1",
    ("Unreacted", "c0"): "m/s", ("Unreacted", "s"): "1", ("Unreacted", "solid_density"): "kg/m³",
    ("BulkViscosity", "quadratic"): "1", ("BulkViscosity", "linear"): "1",
    ("GasContact", "distance"): "× lattice spacing", ("GasContact", "stiffness"): "× ρ₀ vod²",
    ("GasWall", "material"): "—", ("GasWall", "distance"): "× gas lattice spacing",
    ("GasWall", "stiffness"): "× ρ₀ vod²",
    ("TensionFailure", "sigma_st"): "Pa", ("TensionFailure", "c1"): "1",
    ("TensionFailure", "rate0"): "1/s",
    ("Weibull", "modulus"): "1", ("Uniform", "width"): "1", ("Normal", "cv"): "1",
    ("Normal", "truncate"): "standard deviations",
    ("VelocityPulse", "half_width"): "m",
    ("GaussianVelocity", "sigma"): "m",
    ("RadialVelocity", "r_inner"): "m", ("RadialVelocity", "r_outer"): "m",
    ("RadialVelocity", "speed"): "m/s",
    ("Absorbing", "at"): "m", ("Absorbing", "thickness"): "m", ("Absorbing", "reflection"): "1",
    ("PrescribedVelocity", "ramp"): "s",
    ("BoreholePressure", "p0"): "Pa", ("BoreholePressure", "alpha"): "1/s",
    ("BoreholePressure", "beta"): "1/s", ("BoreholePressure", "times"): "s",
    ("BoreholePressure", "pressures"): "Pa",
}

#: allowed values: (class, key) -> (module, constant); a dict constant gives its keys
ALLOWED = {
    ("Multirate", "max_ratio"): ("mpipd.input.scene", "MAX_RATIOS"),
    ("Multirate", "buffer"): ("mpipd.input.scene", "BUFFERS"),
    ("Multirate", "family_factor"): ("mpipd.input.scene", "FAMILY_FACTORS"),
    ("Part", "influence"): ("mpipd.kernels.influence", "CODES"),
    ("JH2", "pressure"): ("mpipd.materials.jh2", "PRESSURES"),
    ("Absorbing", "face"): ("mpipd.input.loads", "FACES"),
    ("VelocityPulse", "axis"): ("mpipd.input.loads", "AXES"),
    ("Distribution", "applies_to"): ("mpipd.materials.heterogeneity", "TARGETS"),
}


# --------------------------------------------------------------------------- the schema

@dataclasses.dataclass
class Key:
    """One key of a table: its field, the class that declares it, its annotation."""
    name: str
    field: dataclasses.Field
    owner: type
    hint: object


def keys(cls) -> list[Key]:
    """The keys a scene may give for ``cls`` (init fields whose type can be built)."""
    hints = typing.get_type_hints(cls)
    out = []
    for f in dataclasses.fields(cls):
        if not f.init or hints[f.name] is type(None):     # e.g. jwl's tension: never a key
            continue
        owner = next(c for c in cls.__mro__ if f.name in getattr(c, "__annotations__", {}))
        out.append(Key(f.name, f, owner, hints[f.name]))
    return out


def registry_of(key: Key):
    """(registry, container) of a tagged field, or None."""
    return key.field.metadata.get("registry")


def unwrap(tp):
    """(inner type, optional?, array?) of an annotation: X | None, tuple[X, ...]."""
    optional = False
    if typing.get_origin(tp) in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(tp) if a is not type(None)]
        optional = len(args) < len(typing.get_args(tp))
        if len(args) == 1:
            tp = args[0]
    array = False
    if typing.get_origin(tp) is tuple:
        args = typing.get_args(tp)
        if len(args) == 2 and args[1] is Ellipsis:
            tp, array = args[0], True
    return tp, optional, array


def child_class(key: Key):
    """The dataclass a key holds (a table or an array of tables), or None."""
    tp, _, _ = unwrap(key.hint)
    return tp if dataclasses.is_dataclass(tp) and isinstance(tp, type) else None


def numeric(key: Key) -> bool:
    """Does the key hold numbers (a number, or an array of them)?"""
    if registry_of(key) is not None or child_class(key) is not None:
        return False
    tp, _, _ = unwrap(key.hint)
    if typing.get_origin(tp) is tuple:
        return all(a in (int, float) for a in typing.get_args(tp))
    return tp in (int, float)


def unit(key: Key) -> str | None:
    for c in key.owner.__mro__:
        if (c.__name__, key.name) in UNITS:
            return UNITS[(c.__name__, key.name)]
    return UNITS_BY_NAME.get(key.name)


def schema_classes() -> list[type]:
    """Every dataclass a scene can hold, the registered kinds included, in page order."""
    seen: list[type] = []

    def visit(cls):
        if cls in seen:
            return
        seen.append(cls)
        for k in keys(cls):
            reg = registry_of(k)
            if reg is not None:
                for name in reg[0].names():
                    visit(reg[0].get(name))
            elif child_class(k) is not None:
                visit(child_class(k))

    visit(scene_module.Scene)
    return seen


def registries() -> list[Registry]:
    """Every registry a scene's tagged tables are resolved through."""
    out = []
    for cls in schema_classes():
        for k in keys(cls):
            reg = registry_of(k)
            if reg is not None and reg[0] not in out:
                out.append(reg[0])
    return out


# --------------------------------------------------------------------------- text from the code

def own_doc(cls) -> str | None:
    """``cls``'s own docstring, not the signature a dataclass makes up without one."""
    doc = cls.__dict__.get("__doc__")
    if not doc or doc.startswith(cls.__name__ + "("):
        return None
    return inspect.cleandoc(doc)


ROLE = re.compile(r":(?:class|func|meth|mod|data|attr):`~?([^`]+)`")


def md(text: str) -> str:
    """A docstring as Markdown: Sphinx roles become code spans (``x`` already is one)."""
    return ROLE.sub(r"`\1`", text)


def line_comments(cls) -> dict[str, str]:
    """The comment on each field's line of the class body (``name: type = x  # comment``)."""
    try:
        src = textwrap.dedent(inspect.getsource(cls))
    except (OSError, TypeError):
        return {}
    out = {}
    pending = []
    tokens = tokenize.generate_tokens(io.StringIO(src).readline)
    line_key, depth = None, 0
    for tok in tokens:
        if tok.type == tokenize.OP and tok.string in "([{":
            depth += 1
        elif tok.type == tokenize.OP and tok.string in ")]}":
            depth -= 1
        if tok.type == tokenize.NAME and tok.start[1] == 4 and depth == 0 and line_key is None:
            line_key = tok.string
        elif tok.type == tokenize.COMMENT:
            text = tok.string.lstrip("#:").strip()
            if tok.start[1] == 4 and line_key is None:       # a "#:" line above a field
                pending.append(text)
            elif line_key is not None:
                out[line_key] = (out.get(line_key, "") + " " + text).strip()
        elif tok.type == tokenize.NEWLINE:
            if line_key is not None and pending:
                out[line_key] = " ".join(pending + [out.get(line_key, "")]).strip()
            pending = [] if line_key is not None else pending
            line_key = None
    return out


GOT = re.compile(r"\s*[;(]\s*got [^)]*\)?\s*$")      # "... (got 3)" at the end
GOT_INSIDE = re.compile(r",\s*got [^)]*\)")            # "(factor >= 1, got 0.5)"


def _message(node) -> str | None:
    """The text of a ``fail`` message, a string or an f-string: ``self.x`` shown as
    the key's name, any other value as "…", without its "got …"; None for anything
    else (a message built by concatenation)."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.JoinedStr):
        parts = []
        for v in node.values:
            if isinstance(v, ast.Constant):
                parts.append(str(v.value))
            elif (isinstance(v, ast.FormattedValue) and isinstance(v.value, ast.Attribute)
                  and isinstance(v.value.value, ast.Name) and v.value.value.id == "self"):
                parts.append(f"`{v.value.attr}`")
            else:
                parts.append("…")
        return GOT.sub("", GOT_INSIDE.sub(")", "".join(parts))) or None
    return None


def _key_of(node) -> str | None:
    """``"x"`` of ``join(path, "x")`` / ``join(join(path, "x"), ...)``."""
    while isinstance(node, ast.Call) and getattr(node.func, "id", None) == "join":
        if (isinstance(node.args[0], ast.Name) and len(node.args) > 1
                and isinstance(node.args[1], ast.Constant)):
            return node.args[1].value
        node = node.args[0]
    return None


def rules(cls) -> dict[str, list[str]]:
    """Per key, the rules of the ``check`` methods of ``cls`` and its bases: "> 0"
    (``positive``), "≥ 0" (``non_negative``) and the messages of ``fail``."""
    out: dict[str, list[str]] = {}
    for c in reversed(cls.__mro__):
        fn = c.__dict__.get("check")
        if fn is None:
            continue
        try:
            tree = ast.parse(textwrap.dedent(inspect.getsource(fn)))
        except (OSError, TypeError, SyntaxError):
            continue
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call) or not isinstance(node.func, ast.Name):
                continue
            name = node.func.id
            if name in ("positive", "non_negative"):
                for a in node.args[2:]:
                    if isinstance(a, ast.Constant):
                        rule = "> 0" if name == "positive" else "≥ 0"
                        out.setdefault(a.value, []).append(rule)
            elif name == "fail" and len(node.args) >= 2:
                key, msg = _key_of(node.args[0]), _message(node.args[1])
                if key and msg and msg.strip():
                    out.setdefault(key, []).append(msg.strip())
    return {k: list(dict.fromkeys(v)) for k, v in out.items()}


#: keys whose allowed values are a table of their own on the page
SEE = {("Output", "fields"): "the names of [Output fields](#output-fields)"}


def allowed(cls, name: str) -> list[str] | None:
    for c in cls.__mro__:
        spec = ALLOWED.get((c.__name__, name))
        if spec is not None:
            value = getattr(importlib.import_module(spec[0]), spec[1])   # a rename fails here
            return [str(v) for v in value]
    return None


# --------------------------------------------------------------------------- rendering

def fmt_number(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float) and v == int(v) and abs(v) < 1e6:
        return str(int(v))
    if isinstance(v, float):
        for p in range(1, 18):
            s = f"{v:.{p}g}"
            if float(s) == v:
                return re.sub(r"e([+-])0*(\d)", lambda m: "e" + m[1].strip("+") + m[2], s)
    return str(v)


def fmt_value(v) -> str:
    if v is None:
        return "absent"
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, (tuple, list)):
        return "[" + ", ".join(fmt_value(x) for x in v) + "]"
    if dataclasses.is_dataclass(v):
        return "a table of its defaults"
    return fmt_number(v)


def default(key: Key, cls) -> str:
    f = key.field
    if key.name in getattr(cls, "required", ()):
        return "**required**"
    if f.default is not dataclasses.MISSING:
        return f"`{fmt_value(f.default)}`" if f.default is not None else "absent"
    if f.default_factory is not dataclasses.MISSING:
        return f"`{fmt_value(f.default_factory())}`"
    return "**required**"


SCALARS = {float: "number", int: "integer", str: "string", bool: "true/false",
           typing.Any: "any"}


def type_name(key: Key, anchors: dict) -> str:
    reg = registry_of(key)
    if reg is not None:
        registry, container = reg
        link = f"[{registry.what}](#{anchors[registry]})"
        table = {None: "table", list: "array of tables", dict: "tables by name"}[container]
        return f"{table}: a {link} (`{registry.tag}`)"
    tp, optional, array = unwrap(key.hint)
    if dataclasses.is_dataclass(tp):
        text = f"[{'array of tables' if array else 'table'}](#{anchors[tp]})"
    elif typing.get_origin(tp) is tuple:
        args = typing.get_args(tp)
        text = f"array of {len(args)} {SCALARS.get(args[0], str(args[0]))}s"
    elif array:
        text = f"array of {SCALARS.get(tp, str(tp))}s"
    else:
        text = SCALARS.get(tp, getattr(tp, "__name__", str(tp)))
    if optional and dataclasses.is_dataclass(tp):
        text += " or `false` (off)"
    return text


def cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def key_table(cls, anchors: dict) -> list[str]:
    comments: dict[str, str] = {}
    for c in reversed(cls.__mro__):
        if dataclasses.is_dataclass(c):
            comments.update(line_comments(c))
    ruled = rules(cls)
    rows = ["| key | type | default | unit | allowed values and rules | comment |",
            "|---|---|---|---|---|---|"]
    for k in keys(cls):
        u = unit(k) if numeric(k) else None
        allow = allowed(cls, k.name)
        text = []
        if allow:
            text.append("one of " + ", ".join(f"`{a}`" for a in allow))
        if (cls.__name__, k.name) in SEE:
            text.append(SEE[(cls.__name__, k.name)])
        text += ruled.get(k.name, [])
        rows.append("| " + " | ".join(cell(x) for x in (
            f"`{k.name}`", type_name(k, anchors), default(k, cls), u or "",
            "; ".join(text), comments.get(k.name, ""))) + " |")
    return rows


def heading(level: int, title: str, anchor: str) -> str:
    return f"{'#' * min(level, 6)} {title} {{#{anchor}}}"


def docs_of(cls) -> list[str]:
    """The docstrings of ``cls`` and of its dataclass bases (each once)."""
    out = []
    doc = own_doc(cls)
    if doc:
        out.append(md(doc))
    for base in cls.__mro__[1:]:
        if dataclasses.is_dataclass(base):
            bdoc = own_doc(base)
            if bdoc:
                out.append(f"From `{base.__name__}`: " + md(bdoc))
    return out


def slug(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-")


class Page:
    """The page, built by walking the schema from :class:`Scene`."""

    def __init__(self):
        self.lines: list[str] = []
        self.anchors: dict = {}
        self.done: set = set()

    def plan(self, cls, path):
        """Give every class and registry an anchor: the path of its first occurrence."""
        for k in keys(cls):
            sub = f"{path}.{k.name}" if path else k.name
            reg = registry_of(k)
            if reg is not None:
                registry = reg[0]
                if registry not in self.anchors:
                    self.anchors[registry] = slug(sub)
                    for name in registry.names():
                        kind = registry.get(name)
                        self.anchors.setdefault(kind, slug(f"{sub}-{name}"))
                        self.plan(kind, f"{sub}.{name}")
            elif child_class(k) is not None and child_class(k) not in self.anchors:
                self.anchors[child_class(k)] = slug(sub)
                self.plan(child_class(k), sub)

    def table(self, cls, title: str, level: int, toml: str | None = None):
        self.done.add(cls)
        self.lines += ["", heading(level, title, self.anchors[cls]), ""]
        if toml:
            self.lines += [f"In a scene: `{toml}`", ""]
        for d in docs_of(cls):
            self.lines += [d, ""]
        self.lines += key_table(cls, self.anchors)
        self.children(cls, level + 1)

    def children(self, cls, level):
        for k in keys(cls):
            reg = registry_of(k)
            if reg is not None and reg[0] not in self.done:
                self.registry(reg[0], level, cls, k)
            elif child_class(k) is not None and child_class(k) not in self.done:
                sub = child_class(k)
                self.table(sub, f"`{k.name}`", level)

    def registry(self, registry: Registry, level, parent, key: Key):
        self.done.add(registry)
        names = registry.names()
        self.lines += ["", heading(level, f"`{key.name}`: {registry.what}s",
                                   self.anchors[registry]), "",
                       f"`{registry.tag}` picks one of: "
                       + ", ".join(f"[`{n}`](#{self.anchors[registry.get(n)]})" for n in names)
                       + ". The other keys of the table are those of the chosen one.", ""]
        for n in names:
            kind = registry.get(n)
            if kind not in self.done:
                self.table(kind, f'`{registry.tag} = "{n}"`', level + 1)

    def render(self) -> str:
        root = scene_module.Scene
        self.plan(root, "")
        top = {k.name: k for k in keys(root)}
        order = [n for n in TOP_ORDER if n in top] + [n for n in top if n not in TOP_ORDER]
        toml = {}
        for n in order:
            k = top[n]
            reg = registry_of(k)
            _, _, array = unwrap(k.hint)
            if reg is not None:
                toml[n] = {list: f"[[{n}]]", dict: f"[{n}.NAME]", None: f"[{n}]"}[reg[1]]
            else:
                toml[n] = f"[[{n}]]" if array else f"[{n}]"
        self.lines += ["| table | keys | required |", "|---|---|---|"]
        for n in order:
            k = top[n]
            target = registry_of(k)[0] if registry_of(k) else child_class(k)
            what = (f"{target.what}s, by `{target.tag}`" if isinstance(target, Registry)
                    else ", ".join(f"`{x.name}`" for x in keys(target)))
            req = "yes" if default(k, root) == "**required**" else "no"
            self.lines.append(f"| [`{toml[n]}`](#{self.anchors[target]}) | {what} | {req} |")
        for n in order:
            k = top[n]
            reg = registry_of(k)
            if reg is not None:
                self.lines += ["", heading(2, f"`{toml[n]}`", self.anchors[reg[0]]), ""]
                self.done.add(reg[0])
                names = reg[0].names()
                self.lines += [f"Each entry names its `{reg[0].tag}`, one of: "
                               + ", ".join(f"[`{x}`](#{self.anchors[reg[0].get(x)]})"
                                           for x in names)
                               + "; its other keys are those of that kind.", ""]
                for x in names:
                    kind = reg[0].get(x)
                    if kind not in self.done:
                        self.table(kind, f'`{reg[0].tag} = "{x}"`', 3)
            else:
                self.table(child_class(k), f"`{toml[n]}`", 2)
        self.lines += output_fields()
        return "\n".join(self.lines).strip() + "\n"


def output_fields() -> list[str]:
    """The names ``[output] fields`` may list, from ``OUTPUT_FIELDS`` and its comments."""
    src = inspect.getsource(scene_module).splitlines()
    start = next(i for i, s in enumerate(src) if s.startswith("OUTPUT_FIELDS"))
    comments = {}
    for line in src[start:]:
        if "#" in line:
            code, note = line.split("#", 1)
            for name in re.findall(r'"(\w+)":', code):
                comments[name] = note.strip()
        if line.strip() == "}":
            break
    needs = {None: "any scene", "failure": "a material that can fail (jh2, or a tension model)",
             "jh2": "a jh2 material", "plastic": "a jh2 or j2 material",
             "pressure": "a jh2 or jwl material", "gas": "a jwl material"}
    rows = ["", heading(3, "Output fields", "output-fields"), "",
            "The names `[output] fields` may list (`mpipd.input.scene.OUTPUT_FIELDS`); each is "
            "written as `/fields/<name>` of `run.h5` (the [output reference](output.md)).", "",
            "| field | columns | needs | comment |", "|---|---|---|---|"]
    for name, (ncol, need) in scene_module.OUTPUT_FIELDS.items():
        rows.append(f"| `{name}` | {ncol} | {needs.get(need, need)} | "
                    f"{cell(comments.get(name, ''))} |")
    return rows


def render() -> str:
    """The generated part of docs/reference/scene.md."""
    return Page().render()


if __name__ == "__main__":
    text = render()
    if len(sys.argv) > 1:
        Path(sys.argv[1]).write_text(text, encoding="utf-8")
    else:
        sys.stdout.write(text)
