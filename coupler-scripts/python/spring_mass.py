#!/usr/bin/env python3
"""A spring-mass-damper body speaking the FSI protocol: the Python twin of `rigid-structure`
for translational DOFs (PROTOCOL §6).

    spring_mass.py run CASE --couple RUN_ID --out DIR [--set key=value]... [--restart CKPT]
    spring_mass.py check CASE [--set key=value]...

It reads `[structure.rigid]` with the keys of `rigid-structure` (mass, dofs among "x", "y",
"z", stiffness, damping, u0, v0 (one number or one per DOF), reference, wet_nodes,
wet_elements, probe), steps the body with the staggered scheme of `[coupling]` (CSS, C0, A6:
`staggered.py`, the formulas of `interface_protocol::coupling`) and writes
`structure_probes.csv` as `rigid-structure` does.

At `Checkpoint { tag }` it writes `OUT/checkpoints/<tag>/structure.ckpt` atomically, in the
project's checkpoint format (`checkpoint.write_checkpoint`, that of `interface_protocol::io::
checkpoint`) and with the content of `rigid-structure`'s part: the step and time of the header,
the DOF names as metadata (a postcard `Vec<String>`), the f64 arrays `u`, `v`, `a`, `v_half` (one
value per DOF) and `coupling.<name>` for each entry of the scheme's history (`staggered.HISTORY`:
`f_half`, `v_half_prev`, `a_hat`, `f_prev`, `times` = [t^n, t_prev, t_half], `f_applied`,
`work`). `--restart CKPT` (the launcher's `fsi run --restart`: a checkpoint tag folder, or a run
folder whose newest `checkpoints/<tag>/structure.ckpt` is taken) reads it back and continues
bitwise; `structure_probes.csv` keeps its rows up to the checkpoint's time.
"""

import argparse
import math
import os
import sys
from decimal import Decimal

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import fsi_peer  # noqa: E402
import checkpoint  # noqa: E402
from checkpoint import CheckpointError  # noqa: E402
from fsi_peer import Failure, StepHeader, SurfaceElement  # noqa: E402
from staggered import HISTORY, Oscillators, Staggered  # noqa: E402

PROG = "spring_mass"
AXES = ["x", "y", "z"]
COMPONENTS = ["ux", "uy", "uz", "vx", "vy", "vz"]
# The checkpoint part this solver writes: `checkpoints/<tag>/structure.ckpt`.
PART = "structure"
CAPABILITIES = fsi_peer.CAPABILITY_RESTART | fsi_peer.CAPABILITY_INTERFACE_WORK


class CaseError(Exception):
    pass


def rust_exp(x):
    """A float as Rust's `{:e}` writes it (shortest round-trip digits): 1e5, -2.5e-3, 0e0."""
    if math.isnan(x):
        return "NaN"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    sign, digits, exp = Decimal(repr(x)).as_tuple()
    ds = "".join(map(str, digits))
    stripped = ds.lstrip("0")
    if not stripped:
        return ("-" if sign else "") + "0e0"
    exp10 = exp + len(ds) - 1 - (len(ds) - len(stripped))
    body = stripped.rstrip("0")
    mantissa = body[0] + ("." + body[1:] if len(body) > 1 else "")
    return ("-" if sign else "") + mantissa + f"e{exp10}"


class Body:
    """The body of a case's `[structure.rigid]` (translations only) and the scheme settings."""

    def __init__(self, path, doc):
        self.file = path

        def fail(field, message):
            raise CaseError(f"{path}: field `{field}`: {message}")

        def number(table, key, field, default=None, positive=False):
            v = table.get(key, default)
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                fail(field, f"expected a number, got {v!r}")
            v = float(v)
            if not math.isfinite(v) or (positive and v <= 0.0):
                fail(field, f"expected a finite number{' > 0' if positive else ''}, got {v}")
            return v

        rigid = doc.get("structure", {}).get("rigid")
        if not isinstance(rigid, dict):
            raise CaseError(f"{path}: {PROG} needs a [structure.rigid] section")
        f = "structure.rigid."
        known = {"mass", "inertia", "dofs", "stiffness", "damping", "u0", "v0", "reference",
                 "wet_nodes", "wet_elements", "probe", "prescribed"}
        for key in rigid:
            if key not in known:
                fail(f + key, "unknown key")
        if rigid.get("prescribed"):
            fail(f + "prescribed", f"prescribed motion is not supported by {PROG}")
        self.mass = number(rigid, "mass", f + "mass", positive=True)
        dofs = rigid.get("dofs", ["x"])
        if not isinstance(dofs, list) or not 1 <= len(dofs) <= 3 or len(set(dofs)) != len(dofs) \
                or any(d not in AXES for d in dofs):
            fail(f + "dofs", f'expected 1 to 3 distinct of "x", "y", "z" ({PROG} moves a body '
                             f"in translation only), got {dofs!r}")
        self.dofs = dofs
        self.axes = [AXES.index(d) for d in dofs]
        n = len(dofs)

        def per_dof(key):
            v = rigid.get(key, 0.0)
            if isinstance(v, list):
                if len(v) != n:
                    fail(f + key, f"expected one number or {n} (one per entry of `dofs`), "
                                  f"got {len(v)}")
                return [number({"v": x}, "v", f"{f}{key}[{i}]") for i, x in enumerate(v)]
            return [number(rigid, key, f + key, 0.0)] * n

        self.k, self.c = per_dof("stiffness"), per_dof("damping")
        if any(x < 0 for x in self.k + self.c):
            fail(f + "stiffness", "expected stiffness and damping >= 0")
        self.u0, self.v0 = per_dof("u0"), per_dof("v0")

        def point(v, field):
            if not isinstance(v, list) or len(v) != 3:
                fail(field, f"expected [x, y, z], got {v!r}")
            return [number({"v": x}, "v", field) for x in v]

        self.reference = np.array(point(rigid.get("reference", [0.0, 0.0, 0.0]),
                                        f + "reference"))
        nodes = rigid.get("wet_nodes", [[0.0, 0.0, 0.0]])
        if not isinstance(nodes, list) or not nodes:
            fail(f + "wet_nodes", "expected at least one node [x, y, z]")
        self.wet_nodes = np.array([point(p, f"{f}wet_nodes[{i}]") for i, p in enumerate(nodes)])
        self.elements = []
        for i, e in enumerate(rigid.get("wet_elements", [])):
            if not isinstance(e, list) or len(e) not in (3, 4) or any(
                    isinstance(j, bool) or not isinstance(j, int) or not 0 <= j < len(nodes)
                    for j in e):
                fail(f"{f}wet_elements[{i}]",
                     f"expected 3 or 4 node indices below {len(nodes)}, got {e!r}")
            el = SurfaceElement(n_nodes=len(e))
            for j, node in enumerate(e):
                el.nodes[j] = node
            for j in range(4):
                el.phi[j] = 1.0
            self.elements.append(el)
        self.probe = rigid.get("probe", "body")
        if not isinstance(self.probe, str) or not self.probe or any(
                ch in self.probe for ch in ',"\n\r'):
            fail(f + "probe", f"a probe name without `,`, `\"` or line breaks, got {self.probe!r}")

        coupling = doc.get("coupling", {})
        self.scheme = coupling.get("scheme", "C0")
        if self.scheme not in ("CSS", "C0", "A6"):
            fail("coupling.scheme", f'expected "CSS", "C0" or "A6", got {self.scheme!r}')
        self.dt = number(coupling, "dt", "coupling.dt", 1e-4, positive=True)
        self.t_end = number(coupling, "t_end", "coupling.t_end", 1e-2, positive=True)
        self.timeout_s = number(coupling, "timeout_s", "coupling.timeout_s", 60.0, positive=True)
        every = doc.get("output", {}).get("probes_every", 1)
        if isinstance(every, bool) or not isinstance(every, int) or every < 1:
            fail("output.probes_every", f"expected an integer >= 1, got {every!r}")
        self.probes_every = every

    def omega_max(self):
        return max([math.sqrt(k / self.mass) for k in self.k if k > 0.0], default=0.0)

    def dt_stable(self):
        """2/ω_max for the central differences of CSS and C0, unlimited for A6."""
        w = self.omega_max()
        return 2.0 / w if self.scheme != "A6" and w > 0.0 else math.inf

    def full(self, q):
        out = [0.0, 0.0, 0.0]
        for axis, x in zip(self.axes, q):
            out[axis] = float(x)
        return out

    def node_states(self, u, v):
        """x = X_ref + u + r, v = v_t for every wet node (a translating body)."""
        uf, vf = self.full(u), self.full(v)
        x = np.array([[self.reference[i] + uf[i] + r[i] for i in range(3)]
                      for r in self.wet_nodes])
        vel = np.array([[vf[i] + 0.0 for i in range(3)] for _ in self.wet_nodes])
        return x, vel

    def reduce(self, loads):
        """The resultant force on the free DOFs, summed node by node."""
        g = [0.0, 0.0, 0.0]
        for f in loads:
            for i in range(3):
                g[i] += float(f[i])
        return np.array([g[a] for a in self.axes])

    def summary(self):
        stable = self.dt_stable()
        stable = f"{stable:e} s" if math.isfinite(stable) else "unlimited"
        return (f"{self.file}: ok: spring-mass body `{self.probe}`, {len(self.dofs)} DOF "
                f"({', '.join(self.dofs)}), {len(self.wet_nodes)} wet nodes, "
                f"{len(self.elements)} wet elements; {self.scheme} dt {self.dt:e} s (stable step "
                f"{stable}), {n_steps(self.dt, self.t_end)} steps to t_end {self.t_end:e} s")


def n_steps(dt, t_end):
    return max(math.ceil(t_end / dt - 1e-9), 1)


class SpringMass:
    """The body through the coupling sequence, as `rigid-structure`'s RigidSolver."""

    def __init__(self, body, out_dir, restart=None):
        self.body = body
        self.out = out_dir
        self.state = Oscillators([body.mass] * len(body.dofs), body.k, body.c, body.u0, body.v0)
        self.scheme = Staggered(body.scheme, len(body.dofs))
        self.first_dt = min(body.dt, body.t_end)
        self.t = 0.0
        self.steps = 0
        kept = ""
        path = os.path.join(out_dir, "structure_probes.csv")
        header = "time" + "".join(f",{body.probe}.{c}" for c in COMPONENTS)
        if restart is not None:
            self.restore(restart_part(restart))
            kept = rows_until(path, header, self.t)
        try:
            self.probes = open(path, "w", encoding="utf-8")
            self.probes.write(header + "\n" + kept)
            self.probes.flush()
        except OSError as e:
            raise CaseError(f"cannot create the probe file {path}: {e.strerror}") from None

    def restore(self, path):
        """Puts back the state, the scheme's history, the step and the time of the part `path`
        (written by `checkpoint`); the error names the file and the array that does not fit."""
        try:
            ck = checkpoint.read_checkpoint(path)
            try:
                names = checkpoint.postcard_strings_decode(ck.meta)
            except (ValueError, UnicodeDecodeError) as e:
                raise CheckpointError(f"checkpoint `{path}`: metadata: {e} (expected the DOF "
                                      "names)") from None
            if names != self.body.dofs:
                raise CheckpointError(f"checkpoint `{path}`: it holds the DOFs {names}, the "
                                      f"case's structure.rigid.dofs are {self.body.dofs}")
            n = len(names)
            d = self.state
            d.u, d.v, d.a, d.v_half = (ck.f64(k, n) for k in ("u", "v", "a", "v_half"))
            missing = [k for k in HISTORY if f"coupling.{k}" not in ck.arrays]
            if missing:
                ck.f64(f"coupling.{missing[0]}")  # raises, naming the file and the array
            try:
                self.scheme.restore(lambda k: ck.f64(f"coupling.{k}"))
            except ValueError as e:
                raise CheckpointError(f"checkpoint `{path}`: {e}") from None
        except CheckpointError as e:
            raise CaseError(str(e)) from None
        self.steps, self.t = ck.step, ck.time

    def _check(self, what, values, t, step, dt):
        for i, x in enumerate(values):
            if not math.isfinite(x):
                message = (f"the rigid body's {what} of DOF \"{self.body.dofs[i]}\" is {x} at "
                           f"t = {t:g} (coupling step {step})")
                stable = self.body.dt_stable()
                if dt > stable:
                    message += (f": the coupling step {dt:g} s diverged; the step is above the "
                                f"stable step {stable:g} s of the rigid model (central "
                                f"differences: dt <= 2/ω_max); lower coupling.dt")
                else:
                    message += ": the integration diverged"
                raise Failure(fsi_peer.CODE_SOLVER, message)

    def _write_probe(self):
        u, v = self.body.full(self.state.u), self.body.full(self.state.v)
        try:
            self.probes.write(",".join(rust_exp(x) for x in [self.t] + u + v) + "\n")
        except OSError as e:
            raise Failure(fsi_peer.CODE_OUTPUT,
                          f"cannot write structure_probes.csv: {e.strerror}") from None

    def _publish(self, peer, step, t, dt, predicted):
        u, v = (self.scheme.up, self.scheme.vp) if predicted else (self.state.u, self.state.v)
        x, vel = self.body.node_states(u, v)
        peer.publish_kinematics(StepHeader(step=step, time=t, dt=dt, topology_version=1), x, vel)

    def _read_loads(self, peer, t, step):
        _, f = peer.read_loads()
        n = len(self.body.wet_nodes)
        if f.shape[0] != n:
            raise Failure(fsi_peer.CODE_PROTOCOL,
                          f"the fluid sent {f.shape[0]} nodal loads, the structure has {n} "
                          "wet nodes")
        bad = np.argwhere(~np.isfinite(f))
        if len(bad):
            node, comp = bad[0]
            raise Failure(fsi_peer.CODE_SOLVER,
                          f"the fluid sent a non-finite load {f[node, comp]} (component "
                          f"{comp}) on wet node {node} at t = {t:g} (coupling step {step})")
        return self.body.reduce(f)

    def init(self, peer):
        """Publishes the topology and the state; a restarted solver publishes the checkpoint's
        state and writes no probe row (its file holds that one)."""
        step, t = self.steps, self.t
        peer.publish_topology(StepHeader(step=step, time=t, topology_version=1),
                              self.body.elements)
        self._publish(peer, step, t, 0.0, False)
        if step == 0:
            self._write_probe()
        return self.body.dt_stable()

    def advance(self, peer, c):
        dt = c.t_to - c.t_from
        s, d = self.scheme, self.state
        if c.scheme_phase == fsi_peer.START:
            first = self.first_dt
            load = self._read_loads(peer, 0.0, c.step)
            publish = s.start(d, load, first)
            for what, x in [("displacement", d.u), ("velocity", d.v), ("acceleration", d.a)]:
                self._check(what, x, 0.0, 0, first)
            if publish:
                self._publish(peer, 0, 0.5 * first, first, True)
        elif c.scheme_phase == fsi_peer.PREDICT:
            load = self._read_loads(peer, c.t_from, c.step) if s.predict_reads_load(c.step) \
                else None
            s.predict(d, dt, load)
            target = s.predicted_time(c.t_from, dt)
            self._check("predicted displacement", s.up, target, c.step, dt)
            self._check("predicted velocity", s.vp, target, c.step, dt)
            self._publish(peer, c.step, target, dt, True)
        elif c.scheme_phase == fsi_peer.CORRECT:
            load = self._read_loads(peer, c.t_to, c.step)
            s.correct(d, load, dt)
            for what, x in [("displacement", d.u), ("velocity", d.v), ("acceleration", d.a)]:
                self._check(what, x, c.t_to, c.step, dt)
            self.t = c.t_to
            self.steps = c.step + 1
            if (c.step + 1) % self.body.probes_every == 0:
                self._write_probe()
        else:
            raise Failure(fsi_peer.CODE_UNSUPPORTED, f"the structure has no Advance phase "
                                                     f"{c.scheme_phase} (expected START, "
                                                     "PREDICT or CORRECT)")
        return c.step, self.t, self.body.dt_stable(), self.scheme.interface_work()

    def checkpoint(self, _peer, tag):
        """Writes `checkpoints/<tag>/structure.ckpt` (the module's docs); flushes the probes
        first."""
        if not tag or tag.startswith(".") or "/" in tag or "\\" in tag:
            raise Failure(fsi_peer.CODE_PROTOCOL, f"checkpoint tag `{tag}` must be non-empty, "
                                                  "not start with `.`, and contain no `/` or `\\`")
        d = self.state
        arrays = [("u", d.u), ("v", d.v), ("a", d.a), ("v_half", d.v_half)]
        arrays += [(f"coupling.{k}", v) for k, v in self.scheme.history()]
        folder = os.path.join(self.out, "checkpoints", tag)
        try:
            self.probes.flush()
            os.makedirs(folder, exist_ok=True)
        except OSError as e:
            raise Failure(fsi_peer.CODE_OUTPUT, f"cannot write the checkpoint: {e.filename}: "
                                                f"{e.strerror}") from None
        try:
            checkpoint.write_checkpoint(os.path.join(folder, f"{PART}.{checkpoint.CKPT_EXTENSION}"),
                                        self.steps, self.t,
                                        checkpoint.postcard_strings(self.body.dofs), arrays)
        except CheckpointError as e:
            raise Failure(fsi_peer.CODE_OUTPUT, f"cannot write the checkpoint: {e}") from None

    def finish(self, _peer):
        try:
            self.probes.flush()
        except OSError as e:
            raise Failure(fsi_peer.CODE_OUTPUT,
                          f"cannot write structure_probes.csv: {e.strerror}") from None


def restart_part(folder):
    """The structure part `--restart folder` names, as `checkpoint::restart_point`: the folder's
    own `structure.ckpt`, else the newest `checkpoints/<tag>/structure.ckpt` under it."""
    name = f"{PART}.{checkpoint.CKPT_EXTENSION}"
    own = os.path.join(folder, name)
    if os.path.isfile(own):
        return own
    checkpoints = os.path.join(folder, "checkpoints")
    try:
        tags = sorted(os.listdir(checkpoints), reverse=True)
    except OSError:
        tags = []
    for tag in tags:
        path = os.path.join(checkpoints, tag, name)
        if os.path.isfile(path):
            return path
    raise CaseError(f"--restart {folder}: no structure checkpoint there (neither {own} nor "
                    f"{checkpoints}/<tag>/{name})")


def rows_until(path, header, t):
    """The rows of the probe file `path` up to time `t` (`ProbeWriter::resume`): its header must
    be `header`; rows a stopped run wrote past `t` are dropped."""
    try:
        with open(path, encoding="utf-8") as f:
            lines = f.read().splitlines()
    except OSError as e:
        raise CaseError(f"cannot continue the probe file {path} at t = {t:e}: "
                        f"{e.strerror}") from None
    found = lines[0] if lines else ""
    if found != header:
        raise CaseError(f"cannot continue the probe file {path} at t = {t:e}: its header is "
                        f"`{found}`, the case's probe gives `{header}`")
    kept = []
    for i, line in enumerate(lines[1:]):
        time = line.split(",", 1)[0]
        try:
            value = float(time)
        except ValueError:
            raise CaseError(f"cannot continue the probe file {path} at t = {t:e}: line {i + 2}: "
                            f"`{time}` is not a time") from None
        if value > t:
            break
        kept.append(line + "\n")
    return "".join(kept)


def prepare(args):
    doc, case_hash = fsi_peer.load_case(args.case, args.set)
    return Body(args.case, doc), case_hash


def run(args):
    body, case_hash = prepare(args)
    if args.couple is None:
        raise CaseError("run needs --couple RUN_ID (the launcher `fsi run` starts it so)")
    out = args.out or "."
    if not os.path.isdir(out):
        raise CaseError(f"the output folder {out} does not exist (the launcher makes it)")
    fsi_peer.install_signal_handlers()
    solver = SpringMass(body, out, args.restart)
    peer = None
    try:
        peer = fsi_peer.StructurePeer(args.couple, len(body.wet_nodes), len(body.elements),
                                      case_hash, body.timeout_s, CAPABILITIES)
        fsi_peer.serve(peer, solver)
    except fsi_peer.Stopped as e:
        raise CaseError(f"run {args.couple} stopped: {e}") from None
    finally:
        solver.probes.close()
        if peer is not None:
            peer.close()


def main(argv):
    parser = argparse.ArgumentParser(prog=PROG, description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    for name in ("run", "check"):
        p = sub.add_parser(name)
        p.add_argument("case")
        p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
        if name == "run":
            p.add_argument("--couple", metavar="RUN_ID")
            p.add_argument("--out", metavar="DIR")
            p.add_argument("--force", action="store_true")
            p.add_argument("--restart", metavar="CKPT")
    args = parser.parse_args(argv)
    try:
        if args.command == "check":
            body, _ = prepare(args)
            print(f"{PROG}: {body.summary()}")
        else:
            run(args)
    except (CaseError, ValueError) as e:
        print(f"{PROG}: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    code = main(sys.argv[1:])
    sys.stdout.flush()
    sys.stderr.flush()
    # Ports and node are gone by now; skipping the interpreter's teardown of the iceoryx2
    # module (over a second) lets the run end within the launcher's bounds (PROTOCOL §5).
    os._exit(code)
