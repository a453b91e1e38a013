"""The FSI coupling protocol (interface-protocol/PROTOCOL.md, version 1) in Python.

A participant written in Python uses this module the way a Rust one uses `interface_protocol`:
the wire types of PROTOCOL §3 (`messages.rs`), the run's iceoryx2 configuration and services of
§1-§2 (`services.rs`, `endpoint/`), the command loop of §4 (`participant.rs`), the liveness
rules of §5 (`liveness.rs`); `checkpoint.py` beside it reads and writes the checkpoint part
files of §4, restart (`io/checkpoint.rs`). It needs the `iceoryx2==0.10.0` and `numpy` packages
(see install.sh).
"""

import ctypes
import gc
import os
import signal
import sys
import time
import tomllib
from decimal import Decimal

import iceoryx2 as iox2
import numpy as np

PROTOCOL_VERSION = 1
ROLE_FLUID, ROLE_STRUCTURE = 1, 2
UNITS_SI = 0

# Command::kind, Command::scheme_phase, Reply::kind and Reply::code of a Failed (PROTOCOL §3).
INIT, ADVANCE, CHECKPOINT, FINISH = 1, 2, 3, 4
NONE, START, PREDICT, CORRECT = 0, 1, 2, 3
READY, DONE, FAILED = 1, 2, 3
CODE_PROTOCOL, CODE_SOLVER, CODE_OUTPUT, CODE_UNSUPPORTED = 1, 2, 3, 4
# Hello.capabilities bits (`messages::capability`, PROTOCOL §3).
CAPABILITY_RESTART, CAPABILITY_INTERFACE_WORK = 1, 2

# A reader sleeps on its wake listener at most this long before it checks whether to stop (§2, §5).
POLL_S = 0.05


class _Wire(ctypes.Structure):
    """A type of PROTOCOL §3: its fields in order in `_fields_`, its iceoryx2 type name in
    `TYPE_NAME` (what the binding asks `type_name()` for)."""

    TYPE_NAME = ""

    @classmethod
    def type_name(cls):
        return cls.TYPE_NAME


class Hello(_Wire):
    """`fsi::Hello::v1`, 48 bytes."""

    TYPE_NAME = "fsi::Hello::v1"
    _fields_ = [
        ("protocol_version", ctypes.c_uint32),
        ("role", ctypes.c_uint32),
        ("pid", ctypes.c_uint32),
        ("units", ctypes.c_uint32),
        ("n_surface_nodes", ctypes.c_uint64),
        ("n_surface_elements", ctypes.c_uint64),
        ("case_hash", ctypes.c_uint64),
        ("capabilities", ctypes.c_uint64),  # CAPABILITY_* bits (PROTOCOL.md §3)
    ]


class Command(_Wire):
    """`fsi::Command::v1`, 96 bytes."""

    TYPE_NAME = "fsi::Command::v1"
    _fields_ = [
        ("kind", ctypes.c_uint32),
        ("scheme_phase", ctypes.c_uint32),
        ("step", ctypes.c_uint64),
        ("t_from", ctypes.c_double),
        ("t_to", ctypes.c_double),
        ("tag", ctypes.c_uint8 * 64),
    ]


class Reply(_Wire):
    """`fsi::Reply::v1`, 312 bytes."""

    TYPE_NAME = "fsi::Reply::v1"
    _fields_ = [
        ("kind", ctypes.c_uint32),
        ("code", ctypes.c_uint32),
        ("step", ctypes.c_uint64),
        ("t", ctypes.c_double),
        ("dt_stable", ctypes.c_double),
        ("work_s", ctypes.c_double),
        ("wait_s", ctypes.c_double),
        ("message", ctypes.c_uint8 * 256),
        ("interface_work", ctypes.c_double),
    ]


class StepHeader(_Wire):
    """`fsi::StepHeader::v1`, 40 bytes: the user header of every surface sample."""

    TYPE_NAME = "fsi::StepHeader::v1"
    _fields_ = [
        ("step", ctypes.c_uint64),
        ("time", ctypes.c_double),
        ("dt", ctypes.c_double),
        ("topology_version", ctypes.c_uint64),
        ("count", ctypes.c_uint64),
    ]


class NodeState(_Wire):
    """`fsi::NodeState::v1`, 48 bytes: position and velocity of a wet node."""

    TYPE_NAME = "fsi::NodeState::v1"
    _fields_ = [("x", ctypes.c_double * 3), ("v", ctypes.c_double * 3)]


class NodeLoad(_Wire):
    """`fsi::NodeLoad::v1`, 24 bytes: the fluid's force on a wet node."""

    TYPE_NAME = "fsi::NodeLoad::v1"
    _fields_ = [("f", ctypes.c_double * 3)]


class SurfaceElement(_Wire):
    """`fsi::SurfaceElement::v1`, 56 bytes: a triangle or quad of the wet surface."""

    TYPE_NAME = "fsi::SurfaceElement::v1"
    _fields_ = [
        ("nodes", ctypes.c_uint32 * 4),
        ("n_nodes", ctypes.c_uint8),
        ("flags", ctypes.c_uint8),
        ("padding", ctypes.c_uint8 * 6),
        ("phi", ctypes.c_double * 4),
    ]


for _t, _size in [(Hello, 48), (Command, 96), (Reply, 312), (StepHeader, 40), (NodeState, 48),
                  (NodeLoad, 24), (SurfaceElement, 56)]:
    assert ctypes.sizeof(_t) == _size and ctypes.alignment(_t) == 8, _t.type_name()


def write_fixed_str(text, buf):
    """Copies `text` NUL-padded into the fixed byte array `buf`, cut at a UTF-8 boundary."""
    data = text.encode("utf-8")[: len(buf)].decode("utf-8", "ignore").encode("utf-8")
    ctypes.memset(buf, 0, len(buf))
    ctypes.memmove(buf, data, len(data))


def read_fixed_str(buf):
    raw = bytes(buf)
    return raw.split(b"\0", 1)[0].decode("utf-8", "replace")


class Failure(Exception):
    """A command that failed: answered with a `Failed` reply of `code` (PROTOCOL §3)."""

    def __init__(self, code, message):
        super().__init__(message)
        self.code = code
        self.message = message


class Stopped(Exception):
    """The participant must end now (a signal, the launcher gone, a deadline missed)."""


# ---- the case file: canonical TOML and its hash (PROTOCOL §3, Hello.case_hash) ----


_FNV_BASIS, _FNV_PRIME, _U64 = 0xCBF29CE484222325, 0x100000001B3, 0xFFFFFFFFFFFFFFFF


def fnv1a64(data):
    h = 0xCBF29CE484222325
    for b in data:
        h = ((h ^ b) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return h


def parse_override(assignment):
    """`key=value` as `interface_protocol::case::apply_override` reads it: the value as TOML, or
    else as a bare string; returns the dotted key's parts and the value."""
    if "=" not in assignment:
        raise ValueError("expected key=value, e.g. coupling.dt=1e-4")
    key, raw = assignment.split("=", 1)
    try:
        value = tomllib.loads("v = " + raw.strip())["v"]
    except tomllib.TOMLDecodeError:
        value = raw.strip()
    parts = [p.strip() for p in key.strip().split(".")]
    if any(not p for p in parts):
        raise ValueError("expected key=value with a dotted key, e.g. coupling.dt=1e-4")
    return parts, value


def apply_override(doc, assignment):
    parts, value = parse_override(assignment)
    table = doc
    for p in parts[:-1]:
        table = table.setdefault(p, {})
        if not isinstance(table, dict):
            raise ValueError(f"`{p}` is not a table")
    table[parts[-1]] = value


def _toml_key(k):
    if k and all(c.isascii() and (c.isalnum() or c in "-_") for c in k):
        return k
    return _toml_string(k)


def _toml_string(s):
    if '"' in s and "'" not in s and "\n" not in s and "\\" not in s:
        return "'" + s + "'"
    out = s.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n").replace("\t", "\\t")
    return '"' + out + '"'


def _toml_float(x):
    """A float as Rust's `Display` writes it (shortest round trip, never an exponent), with the
    `.0` the `toml` crate adds to integral values."""
    if x != x:
        return "nan"
    if x in (float("inf"), float("-inf")):
        return "inf" if x > 0 else "-inf"
    r = repr(x)
    if "e" in r or "E" in r:
        r = format(Decimal(r), "f")
    if "." not in r:
        r += ".0"
    return r


def _toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return _toml_float(v)
    if isinstance(v, str):
        return _toml_string(v)
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        items = ", ".join(f"{_toml_key(k)} = {_toml_value(v[k])}" for k in sorted(v))
        return "{ " + items + " }" if items else "{}"
    return _toml_string(str(v))


def _is_table_array(v):
    return isinstance(v, list) and v and all(isinstance(x, dict) for x in v)


def canonical_toml(doc):
    """`toml::to_string` of the case document as the Rust side hashes it: keys sorted, each
    table's values first, then its sub-tables as `[a.b]` sections and arrays of tables as
    `[[a.b]]`, a table holding only sub-tables left implicit."""
    blocks = []

    def emit(table, path, header, array=False):
        lines = [f"{_toml_key(k)} = {_toml_value(table[k])}" for k in sorted(table)
                 if not isinstance(table[k], dict) and not _is_table_array(table[k])]
        if header is not None and (lines or array or not any(
                isinstance(v, dict) or _is_table_array(v) for v in table.values())):
            blocks.append([header] + lines)
        elif lines:
            blocks.append(lines)
        for k in sorted(table):
            v, sub = table[k], path + [_toml_key(k)]
            if isinstance(v, dict):
                emit(v, sub, "[" + ".".join(sub) + "]")
            elif _is_table_array(v):
                for item in v:
                    emit(item, sub, "[[" + ".".join(sub) + "]]", array=True)

    emit(doc, [], None)
    return "\n".join("\n".join(b) + "\n" for b in blocks)


def load_case(path, overrides):
    """The case document after the `--set` overrides and its hash; errors name the file."""
    try:
        with open(path, "rb") as f:
            doc = tomllib.load(f)
    except OSError as e:
        raise ValueError(f"{path}: cannot read the case file: {e.strerror}") from None
    except tomllib.TOMLDecodeError as e:
        raise ValueError(f"{path}: {e}") from None
    for o in overrides:
        try:
            apply_override(doc, o)
        except ValueError as e:
            raise ValueError(f"{path}: in --set {o}: {e}") from None
    return doc, fnv1a64(canonical_toml(doc).encode("utf-8"))


# ---- liveness (PROTOCOL §5) ----

_stop_signal = None


def _on_signal(signum, _frame):
    global _stop_signal
    _stop_signal = signal.Signals(signum).name


def install_signal_handlers():
    """SIGTERM, SIGINT and SIGHUP ask for a clean stop; with `FSI_LAUNCHER_PID` our parent, the
    kernel sends SIGTERM when the launcher dies (prctl PR_SET_PDEATHSIG)."""
    for s in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
        signal.signal(s, _on_signal)
    pid = launcher_pid()
    if pid is not None and os.getppid() == pid and sys.platform.startswith("linux"):
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, int(signal.SIGTERM), 0, 0, 0)  # PR_SET_PDEATHSIG = 1
        if os.getppid() != pid:
            _on_signal(signal.SIGTERM, None)


def launcher_pid():
    raw = os.environ.get("FSI_LAUNCHER_PID")
    try:
        return int(raw) if raw else None
    except ValueError:
        return None


def check_alive():
    """Raises `Stopped` after a signal or when the launcher is gone."""
    if _stop_signal is not None:
        raise Stopped(f"terminated by {_stop_signal}")
    pid = launcher_pid()
    if pid is None:
        return
    gone = os.getppid() != pid
    if not gone:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            gone = True
        except PermissionError:
            pass
    if gone:
        raise Stopped(f"the launcher (pid {pid}) is gone")


# ---- the run's node and services (PROTOCOL §1, §2) ----


def run_config(run_id):
    if not (1 <= len(run_id) <= 40 and all(c.isascii() and (c.isalnum() or c == "-")
                                           for c in run_id)):
        raise ValueError(f"invalid run id `{run_id}`: expected 1 to 40 characters of A-Z, a-z, "
                         "0-9 or '-'")
    config = iox2.config.default()
    config.global_cfg.prefix = iox2.FileName.new(f"fsi_{run_id}_")
    config.global_cfg.node.cleanup_dead_nodes_on_creation = False
    config.global_cfg.node.cleanup_dead_nodes_on_destruction = False
    config.global_cfg.service.cleanup_dead_nodes_on_open = False
    return config


class StructurePeer:
    """The structure's ports of one run: control server, topology and kinematics publishers,
    loads subscriber, wake events; its `Hello` is published once they all exist."""

    def __init__(self, run_id, n_nodes, n_elements, case_hash, timeout_s, capabilities=0):
        self.run_id = run_id
        self.timeout_s = timeout_s
        self.waited = 0.0
        self._ports = []
        config = run_config(run_id)
        self.node = (iox2.NodeBuilder.new().name(iox2.NodeName.new("structure")).config(config)
                     .signal_handling_mode(iox2.SignalHandlingMode.Disabled)
                     .create(iox2.ServiceType.Ipc))
        try:
            self._open(n_nodes, n_elements, case_hash, capabilities)
        except BaseException:
            self.close()
            raise

    def _service(self, name):
        return self.node.service_builder(iox2.ServiceName.new(f"fsi/{self.run_id}/{name}"))

    def _keep(self, port):
        self._ports.append(port)
        return port

    def _surface(self, name, elem, history):
        svc = (self._service(name).publish_subscribe(iox2.Slice[elem]).user_header(StepHeader)
               .history_size(history).subscriber_max_buffer_size(1).enable_safe_overflow(False)
               .max_publishers(1).open_or_create())
        self._keep(svc)
        return svc

    def _event(self, name):
        return self._keep(self._service(f"wake/{name}").event().open_or_create())

    def _open(self, n_nodes, n_elements, case_hash, capabilities):
        hello_svc = self._keep(
            self._service("hello/structure").publish_subscribe(Hello).history_size(1)
            .subscriber_max_buffer_size(1).enable_safe_overflow(True).open_or_create())
        self.hello_pub = self._keep(hello_svc.publisher_builder().create())
        control = self._keep(
            self._service("control/structure").request_response(Command, Reply)
            .enable_safe_overflow_for_requests(False).enable_safe_overflow_for_responses(False)
            .max_active_requests_per_client(1).max_response_buffer_size(1).open_or_create())
        self.server = self._keep(control.server_builder().create())
        self.topology = self._keep(self._publisher(self._surface("surface/topology",
                                                                 SurfaceElement, 1), n_elements))
        self.kinematics = self._keep(self._publisher(self._surface("surface/kinematics",
                                                                   NodeState, 0), n_nodes))
        loads = self._surface("surface/loads", NodeLoad, 0)
        self.loads = self._keep(loads.subscriber_builder().create())
        self.listener = self._keep(self._event("structure").listener_builder().create())
        self.wake_fluid = self._keep(self._event("fluid").notifier_builder().create())
        self.wake_launcher = self._keep(self._event("launcher").notifier_builder().create())
        hello = Hello(protocol_version=PROTOCOL_VERSION, role=ROLE_STRUCTURE, pid=os.getpid(),
                      units=UNITS_SI, n_surface_nodes=n_nodes, n_surface_elements=n_elements,
                      case_hash=case_hash, capabilities=capabilities)
        self.hello_pub.send_copy(hello)
        self.wake_launcher.notify()

    @staticmethod
    def _publisher(svc, n):
        # Lockstep (§2): at most one sample in flight, so a sample the reader has not taken is
        # discarded by the Python binding's only non-blocking strategy; the fluid reads each.
        return (svc.publisher_builder().allocation_strategy(iox2.AllocationStrategy.PowerOfTwo)
                .initial_max_slice_len(max(n, 1))
                .backpressure_strategy(iox2.BackpressureStrategy.DiscardData).create())

    def close(self):
        """Deletes ports, services and node, newest first (PROTOCOL §6)."""
        for port in reversed(self._ports):
            try:
                port.delete()
            except Exception:  # noqa: BLE001 - best effort while exiting
                pass
        self._ports = []
        # The binding's Node has no delete(): dropping the last reference removes it.
        self.node = None
        gc.collect()

    def _wait(self, poll, what, limit_s):
        """Polls `poll()` until it returns something, sleeping on the wake listener <= 50 ms
        between polls and checking liveness; past `limit_s` fails naming `what`."""
        start = time.monotonic()
        deadline = start + limit_s
        while True:
            got = poll()
            if got is not None:
                self.waited += time.monotonic() - start
                return got
            check_alive()
            now = time.monotonic()
            if now >= deadline:
                raise Stopped(f"no {what} within {limit_s:g} s")
            try:
                self.listener.timed_wait(iox2.Duration.from_secs_f64(min(POLL_S, deadline - now)))
            except iox2.ListenerWaitError:
                pass  # a signal interrupted the wait: check_alive() above tells what to do

    def next_command(self):
        """The launcher's next command (waits 2 timeout + min(timeout, 2 s), PROTOCOL §5)."""
        limit = 2 * self.timeout_s + min(self.timeout_s, 2.0)
        request = self._wait(self.server.receive, "command from the launcher", limit)
        command = Command.from_buffer_copy(request.payload().contents)
        return request, command

    def reply(self, request, reply):
        request.send_copy(reply)
        request.delete()
        self.wake_launcher.notify()

    def _publish(self, publisher, elem, header, values):
        n = len(values) if not isinstance(values, np.ndarray) else values.shape[0]
        sample = publisher.loan_slice_uninit(n)
        header.count = n
        ctypes.memmove(sample.user_header_ptr, ctypes.byref(header), ctypes.sizeof(header))
        if isinstance(values, np.ndarray):
            data = np.ascontiguousarray(values, dtype=np.float64)
            assert data.nbytes == n * ctypes.sizeof(elem)
            ctypes.memmove(sample.payload_ptr, data.ctypes.data, data.nbytes)
        else:
            for i, v in enumerate(values):
                ctypes.memmove(sample.payload_ptr + i * ctypes.sizeof(elem), ctypes.byref(v),
                               ctypes.sizeof(elem))
        sample.assume_init().send()
        self.wake_fluid.notify()

    def publish_topology(self, header, elements):
        """Publishes the wet-surface elements (a list of `SurfaceElement`)."""
        self._publish(self.topology, SurfaceElement, header, elements)

    def publish_kinematics(self, header, x, v):
        """Publishes the wet nodes' positions `x` and velocities `v` (n x 3 arrays)."""
        self._publish(self.kinematics, NodeState, header, np.hstack([x, v]))

    def read_loads(self):
        """The fluid's next loads: its header and an n x 3 array of nodal forces."""
        sample = self._wait(self.loads.receive, "loads from the fluid", self.timeout_s)
        header = StepHeader.from_buffer_copy(sample.user_header().contents)
        n = sample.header.number_of_elements
        if header.count != n:
            raise Failure(CODE_PROTOCOL, f"the loads' header counts {header.count} nodes, the "
                                         f"slice holds {n}")
        raw = (ctypes.c_double * (3 * n)).from_address(sample.payload_ptr)
        f = np.array(raw, dtype=np.float64).reshape(n, 3)
        sample.delete()
        return header, f


def serve(peer, handler):
    """Answers commands until `Finish` (PROTOCOL §4): `handler.init(peer)` returns dt_stable,
    `handler.advance(peer, command)` returns (step, t, dt_stable, interface_work),
    `handler.checkpoint(peer, tag)` and `handler.finish(peer)`; `Checkpoint` and `Finish` repeat
    the last `Advance`'s progress. A `Failure` becomes a `Failed` reply, the loop goes on until
    `Finish`."""
    step, t, dt_stable, work = 0, 0.0, float("inf"), 0.0
    while True:
        request, command = peer.next_command()
        start = time.monotonic()
        peer.waited = 0.0
        reply = Reply(dt_stable=dt_stable)
        try:
            if command.kind == INIT:
                dt_stable = handler.init(peer)
                reply.kind = READY
            elif command.kind == ADVANCE:
                step, t, dt_stable, work = handler.advance(peer, command)
                reply.kind = DONE
            elif command.kind == CHECKPOINT:
                handler.checkpoint(peer, read_fixed_str(command.tag))
                reply.kind = DONE
            elif command.kind == FINISH:
                handler.finish(peer)
                reply.kind = DONE
            else:
                raise Failure(CODE_PROTOCOL, f"unknown command kind {command.kind}")
            reply.step, reply.t, reply.dt_stable = step, t, dt_stable
            reply.interface_work = work if command.kind != INIT else 0.0
        except Failure as f:
            reply = Reply(kind=FAILED, code=f.code, dt_stable=dt_stable)
            write_fixed_str(f.message, reply.message)
        except (Stopped, KeyboardInterrupt):
            raise
        except Exception as e:  # noqa: BLE001 - a solver bug is reported, not a crash
            reply = Reply(kind=FAILED, code=CODE_SOLVER, dt_stable=dt_stable)
            write_fixed_str(f"internal error: {type(e).__name__}: {e}", reply.message)
        reply.wait_s = peer.waited
        reply.work_s = max(time.monotonic() - start - peer.waited, 0.0)
        peer.reply(request, reply)
        if command.kind == FINISH:
            return
