"""The structure side of the staggered schemes CSS, C0 and A6 (DESIGN §4, thesis §3.2 after
Farhat, van der Zee and Geuzaine, CMAME 2006): a line-by-line port of
`interface_protocol::coupling` (`Staggered`, `Oscillators`), so a Python participant takes the
same steps as the Rust ones, to the last bit on the same operations. Every array is a numpy
vector of generalized coordinates; `dt` is the length of the step being taken (the shortened
last step uses its own).
"""

import numpy as np

# α0 and α1 of the C0 position predictor (third order).
C0_ALPHA0 = 0.5
C0_ALPHA1 = 0.375


def kick(v, a, h):
    """v + h a (central-difference half kick)."""
    return v + h * a


def drift(u, v, h):
    """u + h v (central-difference drift)."""
    return kick(u, v, h)


def c0_start_prediction(u, v, a, dt):
    """C0 start: the state predicted for t^{1/2}, u + Δt/2 v + Δt²/8 a and v + Δt/2 a."""
    return u + 0.5 * dt * v + dt * dt / 8.0 * a, v + 0.5 * dt * a


def c0_prediction(u_next, v_half, v_half_prev, dt):
    """C0 predictor for t^{n+3/2}: u^{n+1} + Δt(α0+α1) v^{n+1/2} - Δt α1 v^{n-1/2} and
    2 v^{n+1/2} - v^{n-1/2}."""
    up = u_next + dt * (C0_ALPHA0 + C0_ALPHA1) * v_half - dt * C0_ALPHA1 * v_half_prev
    return up, 2.0 * v_half - v_half_prev


def c0_load_average(f_before, f_after):
    """C0 load at t^{n+1}: (F^{n+1/2} + F^{n+3/2}) / 2."""
    return 0.5 * (f_before + f_after)


def a6_prediction(u, v, a_hat, dt):
    """A6 predictor for t^{n+1/2}: u^n + Δt/2 v^n, v^n + Δt/2 â^n."""
    return drift(u, v, 0.5 * dt), kick(v, a_hat, 0.5 * dt)


def a6_acceleration_estimate(v, v_prev, dt):
    """â^n = (v^n - v^{n-1}) / Δt."""
    return (v - v_prev) / dt


def load_line(ta, fa, tb, fb, t):
    """The load through (ta, fa), (tb, fb) at t: fb + (t - tb)/(tb - ta) (fb - fa)."""
    s = (t - tb) / (tb - ta)
    return fb + s * (fb - fa)


def load_between(f_from, f_to, s):
    """CSS substep load: (1 - s) F^n + s F^{n+1}."""
    return (1.0 - s) * f_from + s * f_to


class Oscillators:
    """Uncoupled linear oscillators m a + c v + k u = f, with their state u, v, a, v^{n+1/2}."""

    def __init__(self, m, k, c, u0, v0):
        self.m, self.k, self.c = (np.asarray(x, dtype=np.float64) for x in (m, k, c))
        self.u = np.array(u0, dtype=np.float64)
        self.v = np.array(v0, dtype=np.float64)
        self.a = np.zeros_like(self.u)
        self.v_half = np.zeros_like(self.u)

    def _acceleration(self, f, u, v_half, h):
        """The a that solves m a = f - k u - c (v_half + h a)."""
        return (f - self.k * u - self.c * v_half) / (self.m + self.c * h)

    def start(self, f0):
        self.a = self._acceleration(f0, self.u, self.v, 0.0)

    def advance_positions(self, dt):
        self.v_half = kick(self.v, self.a, 0.5 * dt)
        self.u = self.u + dt * self.v_half

    def complete(self, f, dt):
        self.a = self._acceleration(f, self.u, self.v_half, 0.5 * dt)
        self.v = kick(self.v_half, self.a, 0.5 * dt)

    def implicit_midpoint(self, f, dt):
        """u^{n+1} = u^n + Δt/2 (v^n + v^{n+1}), m (v^{n+1} - v^n) = Δt (f - k ū - c v̄); with
        s = v^n + v^{n+1}: s (m + Δt² k/4 + Δt c/2) = 2 m v^n + Δt (f - k u^n)."""
        m, k, c, v0 = self.m, self.k, self.c, self.v
        s = (2.0 * m * v0 + dt * (f - k * self.u)) / (m + dt * dt * k / 4.0 + dt * c / 2.0)
        self.u = self.u + 0.5 * dt * s
        self.v = s - v0
        self.a = (self.v - v0) / dt


class Ledger:
    """The work of the applied load on the displacement (`coupling::Ledger`): a central-
    difference substep from u^k to u^{k+1} with the loads F^k (the previous substep's, F^0 at
    START) and F^{k+1} adds (F^k + F^{k+1})/2 · (u^{k+1} - u^k); an implicit midpoint step
    with F held adds F · (u^{n+1} - u^n). Summed component by component in order, as Rust's
    `Iterator::sum`."""

    def __init__(self, n):
        self.f_applied = np.zeros(n)
        self.u_before = np.zeros(n)
        self.work = 0.0

    def begin(self, d):
        self.u_before = d.u.copy()

    def end(self, d, f, held):
        after, before, applied = d.u, self.u_before, self.f_applied
        total = 0.0
        for i in range(len(f)):
            load = f[i] if held else 0.5 * (applied[i] + f[i])
            total += float(load * (after[i] - before[i]))
        self.work += total
        self.f_applied = np.array(f, dtype=np.float64)


# The names of `Staggered.history`, in `coupling::Staggered::history`'s order.
HISTORY = ["f_half", "v_half_prev", "a_hat", "f_prev", "times", "f_applied", "work"]


class Staggered:
    """The scheme's state through START, PREDICT and CORRECT (`coupling::Staggered`), with
    `m` central-difference substeps per coupling step for CSS and C0 (PROTOCOL §4), and the
    energy ledger (`interface_work`)."""

    def __init__(self, scheme, n, fixed_substeps=None):
        z = np.zeros(n)
        self.scheme = scheme
        self.up, self.vp = z.copy(), z.copy()
        self.v_half_prev, self.f_half, self.t_half = z.copy(), z.copy(), 0.0
        self.a_hat = z.copy()
        self.f_prev, self.t_prev = z.copy(), 0.0
        self.v_mid = z.copy()
        self.t = 0.0
        self.stable_step = float("inf")
        self.fixed_substeps = fixed_substeps
        self.n_substeps = 1
        self.ledger = Ledger(n)

    def interface_work(self):
        """The work of the applied loads on the displacement from t = 0 (`Ledger`)."""
        return self.ledger.work

    def history(self):
        """What a checkpoint keeps, named as `coupling::Staggered::history`: C0's F^{n+1/2} and
        v^{n-1/2}, A6's â^n, the load sample before, the times [t^n, t_prev, t_half], the
        ledger's last applied load and its work."""
        return [
            ("f_half", self.f_half.copy()),
            ("v_half_prev", self.v_half_prev.copy()),
            ("a_hat", self.a_hat.copy()),
            ("f_prev", self.f_prev.copy()),
            ("times", np.array([self.t, self.t_prev, self.t_half])),
            ("f_applied", self.ledger.f_applied.copy()),
            ("work", np.array([self.ledger.work])),
        ]

    def restore(self, get):
        """Puts back the `history` that `get(name)` returns (None: missing), after CORRECT of
        the step the checkpoint closed; raises ValueError naming a missing or mis-sized entry."""
        n = len(self.f_half)

        def take(name, size):
            v = get(name)
            if v is None:
                raise ValueError(f"coupling history `{name}` is missing")
            v = np.array(v, dtype=np.float64)
            if v.size != size:
                raise ValueError(f"coupling history `{name}` holds {v.size} values, expected "
                                 f"{size}")
            return v

        self.f_half = take("f_half", n)
        self.v_half_prev = take("v_half_prev", n)
        self.a_hat = take("a_hat", n)
        self.f_prev = take("f_prev", n)
        self.t, self.t_prev, self.t_half = (float(x) for x in take("times", 3))
        self.ledger.f_applied = take("f_applied", n)
        self.ledger.work = float(take("work", 1)[0])

    def substeps(self, dt):
        if self.scheme == "A6":
            return 1
        if self.fixed_substeps is not None:
            return max(self.fixed_substeps, 1)
        if np.isfinite(self.stable_step) and self.stable_step > 0.0:
            return max(int(np.ceil(dt / self.stable_step * (1.0 - 1e-12))), 1)
        return 1

    def start(self, d, f0, dt):
        """START with F^0; returns whether up/vp hold kinematics to publish (C0: t^{1/2})."""
        d.start(f0)
        self.a_hat = d.a.copy()
        self.f_prev = np.array(f0, dtype=np.float64)
        self.ledger.f_applied = self.f_prev.copy()
        self.t_prev = self.t
        if self.scheme == "C0":
            self.v_half_prev = kick(d.v, d.a, -0.5 * dt)
            self.up, self.vp = c0_start_prediction(d.u, d.v, d.a, dt)
            return True
        return False

    def predict_reads_load(self, step):
        """Whether PREDICT of `step` first consumes a load (C0, step 0: F^{1/2})."""
        return self.scheme == "C0" and step == 0

    def predicted_time(self, t_from, dt):
        return {"CSS": t_from, "C0": t_from + 1.5 * dt, "A6": t_from + 0.5 * dt}[self.scheme]

    def predict(self, d, dt, load=None):
        if self.scheme == "CSS":
            self.up, self.vp = d.u.copy(), d.v.copy()
        elif self.scheme == "C0":
            if load is not None:
                self.f_half = np.array(load, dtype=np.float64)
                self.t_half = self.t + 0.5 * dt
            self._c0_drift(d, dt)
            self.up, self.vp = c0_prediction(d.u, self.v_mid, self.v_half_prev, dt)
        else:
            self.up, self.vp = a6_prediction(d.u, d.v, self.a_hat, dt)

    def _c0_drift(self, d, dt):
        """C0 at PREDICT: the substeps to u^{n+1} but the last one's second half, with the load
        extrapolated through the last two samples; keeps the midpoint velocity."""
        m = self.substeps(dt)
        self.n_substeps = m
        h = dt / m
        for k in range(1, m + 1):
            self.ledger.begin(d)
            d.advance_positions(h)
            if 2 * k - 1 == m:
                self.v_mid = d.v_half.copy()
            if k == m:
                break
            tk = self.t + k * h
            f = load_line(self.t_prev, self.f_prev, self.t_half, self.f_half, tk)
            d.complete(f, h)
            self.ledger.end(d, f, False)
            if 2 * k == m:
                self.v_mid = d.v.copy()

    def correct(self, d, load, dt):
        """CORRECT with the load just returned (CSS F^{n+1}, C0 F^{n+3/2}, A6 F^{n+1/2})."""
        load = np.array(load, dtype=np.float64)
        if self.scheme == "CSS":
            m = self.substeps(dt)
            h = dt / m
            for k in range(1, m + 1):
                self.ledger.begin(d)
                d.advance_positions(h)
                f = load_between(self.f_prev, load, k / m)
                d.complete(f, h)
                self.ledger.end(d, f, False)
            self.f_prev = load
        elif self.scheme == "C0":
            f = c0_load_average(self.f_half, load)
            d.complete(f, dt / self.n_substeps)
            self.ledger.end(d, f, False)
            self.v_half_prev = self.v_mid.copy()
            self.f_prev, self.t_prev = self.f_half, self.t_half
            self.f_half, self.t_half = load, self.t + 1.5 * dt
        else:
            v_prev = d.v.copy()
            self.ledger.begin(d)
            d.implicit_midpoint(load, dt)
            self.ledger.end(d, load, True)
            self.a_hat = a6_acceleration_estimate(d.v, v_prev, dt)
        self.t += dt
