//! The checks of `[structure]` that need no mesh: finite numbers, positive sizes, known
//! materials, a thickness on shells and a section on beams, static settings with the static
//! integrator, and step counts within `resources::MAX_STEPS`. Each error is the field and what
//! was expected.

use super::*;

impl CurveSpec {
    fn validate(&self, field: &str) -> Result<(), (String, String)> {
        match self {
            CurveSpec::Named(_) => Ok(()),
            CurveSpec::Ramp(r) => crate::case::require_positive(&format!("{field}.ramp"), r.ramp),
            CurveSpec::Table(t) => {
                let ok = !t.table.is_empty()
                    && t.table.iter().flatten().all(|v| v.is_finite())
                    && t.table.windows(2).all(|w| w[1][0] > w[0][0]);
                if ok {
                    Ok(())
                } else {
                    Err((
                        format!("{field}.table"),
                        "expected at least one finite [t, value] point, t strictly increasing"
                            .into(),
                    ))
                }
            }
        }
    }
}

fn finite(field: &str, v: &[f64]) -> Result<(), (String, String)> {
    match v.iter().find(|x| !x.is_finite()) {
        Some(x) => Err((field.to_string(), format!("expected finite numbers, got {x}"))),
        None => Ok(()),
    }
}

fn at_least_one(field: &str, n: usize, what: &str) -> Result<(), (String, String)> {
    if n == 0 {
        Err((field.to_string(), format!("expected at least one {what}")))
    } else {
        Ok(())
    }
}

fn angles(field: &str, a: [f64; 2], lo: f64, hi: f64) -> Result<(), (String, String)> {
    if a.iter().all(|v| v.is_finite() && *v >= lo && *v <= hi) && a[1] > a[0] {
        Ok(())
    } else {
        Err((field.to_string(), format!("expected {lo} <= start < end <= {hi}, got {a:?}")))
    }
}

impl StructureMesh {
    fn validate(&self) -> Result<(), (String, String)> {
        use crate::case::require_positive as pos;
        let f = |k: &str| format!("structure.mesh.{k}");
        match self {
            StructureMesh::Rectangle { lx, ly, nx, ny, .. } => {
                pos(&f("lx"), *lx)?;
                pos(&f("ly"), *ly)?;
                at_least_one(&f("nx"), *nx, "cell")?;
                at_least_one(&f("ny"), *ny, "cell")
            }
            StructureMesh::Cylinder { radius, length, n_theta, n_axial, theta_deg, .. } => {
                pos(&f("radius"), *radius)?;
                pos(&f("length"), *length)?;
                at_least_one(&f("n_theta"), *n_theta, "cell")?;
                at_least_one(&f("n_axial"), *n_axial, "cell")?;
                angles(&f("theta_deg"), *theta_deg, -360.0, 360.0)
            }
            StructureMesh::Sphere { radius, n_theta, n_phi, theta_deg, phi_deg, .. } => {
                pos(&f("radius"), *radius)?;
                at_least_one(&f("n_theta"), *n_theta, "cell")?;
                at_least_one(&f("n_phi"), *n_phi, "cell")?;
                angles(&f("theta_deg"), *theta_deg, -360.0, 360.0)?;
                angles(&f("phi_deg"), *phi_deg, 0.0, 180.0)
            }
            StructureMesh::Annulus { r_inner, r_outer, n_theta, n_r, theta_deg, .. } => {
                if !(r_inner.is_finite() && *r_inner >= 0.0 && r_outer > r_inner) {
                    return Err((
                        f("r_outer"),
                        format!("expected 0 <= r_inner < r_outer, got {r_inner} and {r_outer}"),
                    ));
                }
                at_least_one(&f("n_theta"), *n_theta, "cell")?;
                at_least_one(&f("n_r"), *n_r, "cell")?;
                angles(&f("theta_deg"), *theta_deg, -360.0, 360.0)
            }
            StructureMesh::Line { from, to, n } => {
                finite(&f("from"), from)?;
                finite(&f("to"), to)?;
                if from == to {
                    return Err((f("to"), "expected a point other than `from`".into()));
                }
                at_least_one(&f("n"), *n, "cell")
            }
            StructureMesh::Gmsh { file, .. } => {
                if file.is_empty() {
                    return Err((f("file"), "expected a gmsh file name".into()));
                }
                Ok(())
            }
        }
    }
}

impl StructureMaterial {
    fn validate(&self, field: &str) -> Result<(), (String, String)> {
        use crate::case::require_positive;
        require_positive(&format!("{field}.e"), self.e)?;
        require_positive(&format!("{field}.rho"), self.rho)?;
        if !(self.nu > -1.0 && self.nu < 0.5) {
            return Err((
                format!("{field}.nu"),
                format!("expected -1 < nu < 0.5, got {}", self.nu),
            ));
        }
        if let Some(sy) = self.sigma_y {
            require_positive(&format!("{field}.sigma_y"), sy)?;
        }
        if !(self.hardening >= 0.0 && self.hardening.is_finite()) {
            return Err((
                format!("{field}.hardening"),
                format!("expected a finite number >= 0, got {}", self.hardening),
            ));
        }
        Ok(())
    }
}

impl StructureSection {
    pub(crate) fn validate(&self) -> Result<(), (String, String)> {
        use crate::case::require_positive;
        if let Some(r) = &self.rigid {
            r.validate()?;
        }
        if let Some(m) = &self.mesh {
            m.validate()?;
        }
        if let Some(m) = &self.material {
            if self.materials.contains_key("default") {
                return Err((
                    "structure.materials.default".into(),
                    "`material` is the material named \"default\"; give one or the other".into(),
                ));
            }
            m.validate("structure.material")?;
        }
        for (name, m) in &self.materials {
            m.validate(&format!("structure.materials.{name}"))?;
        }
        for (field, v) in [
            ("structure.thickness", self.thickness),
            ("structure.dt", self.dt),
            ("structure.t_end", self.t_end),
        ] {
            if let Some(v) = v {
                require_positive(field, v)?;
            }
        }
        if let Some(s) = self.safety {
            if !(s > 0.0 && s <= 1.0) {
                return Err((
                    "structure.safety".into(),
                    format!("expected 0 < safety <= 1, got {s}"),
                ));
            }
        }
        self.validate_parts()?;
        self.validate_analysis()?;
        for (name, b) in &self.sets {
            finite(&format!("structure.sets.{name}"), &[b.min, b.max].concat())?;
        }
        for (k, b) in self.bc.iter().enumerate() {
            let f = format!("structure.bc[{k}]");
            let given = [!b.fixed.is_empty(), b.symmetry.is_some(), b.prescribed.is_some()];
            if given.iter().filter(|g| **g).count() != 1 {
                return Err((
                    f,
                    "expected exactly one of `fixed = [dofs]`, `symmetry = \"x|y|z\"` (or a \
                     normal `[nx, ny, nz]`), \
                     `prescribed = { dof, value, curve }`"
                        .into(),
                ));
            }
            if let Some(Symmetry::Normal(n)) = b.symmetry {
                finite(&format!("{f}.symmetry"), &n)?;
                if n.iter().all(|c| *c == 0.0) {
                    return Err((format!("{f}.symmetry"), "expected a non-zero normal".into()));
                }
            }
            if let Some(p) = &b.prescribed {
                finite(&format!("{f}.prescribed.value"), &[p.value])?;
                if let Some(c) = &p.curve {
                    c.validate(&format!("{f}.prescribed.curve"))?;
                }
            }
        }
        let mut gravity = 0;
        for (k, l) in self.loads.iter().enumerate() {
            let f = format!("structure.loads[{k}]");
            let Some(kind) = l.kind() else {
                return Err((
                    f,
                    "expected a point load (`set`, `dof`, `value`), a `pressure` (with an \
                     optional `set`) or a `gravity` vector"
                        .into(),
                ));
            };
            match kind {
                LoadKind::Point { value, .. } => finite(&format!("{f}.value"), &[value])?,
                LoadKind::Pressure { p, .. } => {
                    if l.dof.is_some() {
                        return Err((
                            format!("{f}.dof"),
                            "a pressure acts along the normal; remove `dof`".into(),
                        ));
                    }
                    finite(&format!("{f}.pressure"), &[p])?
                }
                LoadKind::Gravity(g) => {
                    if l.set.is_some() || l.dof.is_some() {
                        return Err((
                            format!("{f}.gravity"),
                            "gravity acts on every node; remove `set` and `dof`".into(),
                        ));
                    }
                    gravity += 1;
                    if gravity > 1 {
                        return Err((format!("{f}.gravity"), "expected one gravity load".into()));
                    }
                    finite(&format!("{f}.gravity"), &g)?
                }
            }
            if let Some(c) = &l.curve {
                c.validate(&format!("{f}.curve"))?;
            }
        }
        for (k, r) in self.rigid_bodies.iter().enumerate() {
            let f = format!("structure.rigid_bodies[{k}]");
            if let Some(p) = r.reference {
                finite(&format!("{f}.reference"), &p)?;
            }
            if !(r.mass >= 0.0 && r.mass.is_finite()) {
                return Err((
                    format!("{f}.mass"),
                    format!("expected a finite mass >= 0, got {}", r.mass),
                ));
            }
            if r.reference.is_some() && r.reference_set.is_some() {
                return Err((
                    format!("{f}.reference_set"),
                    "give `reference` (a new node at a point) or `reference_set` (an existing \
                     node), not both"
                        .into(),
                ));
            }
            if let Some(spring) = &r.spring {
                spring.validate(&format!("{f}.spring"))?;
            }
            if let Some(j) = &r.inertia {
                for (i, row) in j.iter().enumerate() {
                    finite(&format!("{f}.inertia[{i}]"), row)?;
                }
                let mut asym = (0..3).flat_map(|i| (0..3).map(move |k| (i, k)));
                if let Some((i, k)) = asym.find(|&(i, k)| j[i][k] != j[k][i]) {
                    return Err((
                        format!("{f}.inertia"),
                        format!(
                            "expected a symmetric tensor, got inertia[{i}][{k}] = {} and \
                             inertia[{k}][{i}] = {}",
                            j[i][k], j[k][i]
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Parts: known materials, a thickness on shells, a section on beams.
    fn validate_parts(&self) -> Result<(), (String, String)> {
        let materials = self.all_materials();
        let known = || materials.keys().cloned().collect::<Vec<_>>().join(", ");
        if !self.parts.is_empty() {
            for (field, given) in [
                ("structure.element", self.element.is_some()),
                ("structure.thickness", self.thickness.is_some()),
            ] {
                if given {
                    return Err((
                        field.into(),
                        "give the element and thickness in each [[structure.parts]] entry when \
                         there are parts"
                            .into(),
                    ));
                }
            }
        }
        for (k, p) in self.parts.iter().enumerate() {
            let f = format!("structure.parts[{k}]");
            match &p.material {
                Some(m) if !materials.contains_key(m) => {
                    return Err((
                        format!("{f}.material"),
                        format!("no material \"{m}\"; known materials: {}", known()),
                    ))
                }
                None if materials.len() != 1 => {
                    return Err((
                        format!("{f}.material"),
                        format!("expected the name of one of the materials: {}", known()),
                    ))
                }
                _ => {}
            }
            let shell = matches!(
                p.element,
                ElementType::Bt4 | ElementType::Mitc4 | ElementType::Dkt | ElementType::Shell
            );
            match (shell, p.thickness) {
                (true, None) => {
                    return Err((format!("{f}.thickness"), "expected the shell thickness".into()))
                }
                (true, Some(h)) => crate::case::require_positive(&format!("{f}.thickness"), h)?,
                (false, Some(_)) => {
                    return Err((format!("{f}.thickness"), "only shells have a thickness".into()))
                }
                (false, None) => {}
            }
            if let Some(n) = p.points {
                if !shell || !(1..=10).contains(&n) {
                    return Err((
                        format!("{f}.points"),
                        "expected 1 to 10 Gauss points through a shell's thickness".into(),
                    ));
                }
            }
            match (p.element == ElementType::Beam, &p.section, p.up) {
                (true, Some(s), Some(up)) => {
                    let full = [s.area, s.iy, s.iz, s.j];
                    let ok = match (s.rectangle, full.iter().all(Option::is_some)) {
                        (Some(r), false) if full.iter().all(Option::is_none) => {
                            r.iter().all(|v| v.is_finite() && *v > 0.0)
                        }
                        (None, true) => full.iter().flatten().all(|v| v.is_finite() && *v > 0.0),
                        _ => false,
                    };
                    if !ok {
                        return Err((
                            format!("{f}.section"),
                            "expected { rectangle = [b, h] } or { area, iy, iz, j }, all > 0"
                                .into(),
                        ));
                    }
                    finite(&format!("{f}.up"), &up)?;
                    if up == [0.0; 3] {
                        return Err((format!("{f}.up"), "expected a nonzero vector".into()));
                    }
                }
                (true, None, _) => {
                    return Err((format!("{f}.section"), "a beam needs a section".into()))
                }
                (true, _, None) => {
                    return Err((format!("{f}.up"), "a beam needs an `up` vector".into()))
                }
                (false, Some(_), _) => {
                    return Err((format!("{f}.section"), "only beams have a section".into()))
                }
                (false, _, Some(_)) => {
                    return Err((format!("{f}.up"), "only beams have an `up` vector".into()))
                }
                (false, None, None) => {}
            }
        }
        Ok(())
    }

    /// Static settings only with `integrator = "static"`.
    fn validate_analysis(&self) -> Result<(), (String, String)> {
        let statics = self.integrator() == Integrator::Static;
        for (field, given) in [
            ("structure.steps", self.steps.is_some()),
            ("structure.newton", self.newton.is_some()),
            ("structure.control", self.control.is_some()),
            ("structure.arc_length", self.arc_length.is_some()),
        ] {
            if given && !statics {
                return Err((field.into(), "applies to integrator = \"static\" only".into()));
            }
        }
        if statics && self.dt.is_some() {
            return Err((
                "structure.dt".into(),
                "a static run steps the load factor; give `steps` instead".into(),
            ));
        }
        if self.steps == Some(0) {
            return Err(("structure.steps".into(), "expected at least one load step".into()));
        }
        if let Some(n) = self.steps.filter(|&n| n as u64 > crate::resources::MAX_STEPS) {
            return Err((
                "structure.steps".into(),
                format!(
                    "{n} load steps is more than the {} one run may take",
                    crate::resources::MAX_STEPS
                ),
            ));
        }
        if let Some(n) = &self.newton {
            if let Some(t) = n.tol {
                crate::case::require_positive("structure.newton.tol", t)?;
            }
            if n.max_iter == Some(0) {
                return Err(("structure.newton.max_iter".into(), "expected at least 1".into()));
            }
        }
        if let Some(a) = &self.arc_length {
            if self.control.is_some() {
                return Err((
                    "structure.arc_length".into(),
                    "give one of `control` and `arc_length`".into(),
                ));
            }
            crate::case::require_positive("structure.arc_length.initial", a.initial)?;
            if !(a.min() > 0.0 && a.min() <= a.initial && a.initial <= a.max()) {
                return Err((
                    "structure.arc_length".into(),
                    format!(
                        "expected 0 < min <= initial <= max, got {} <= {} <= {}",
                        a.min(),
                        a.initial,
                        a.max()
                    ),
                ));
            }
            if a.desired_iterations == Some(0) {
                return Err((
                    "structure.arc_length.desired_iterations".into(),
                    "expected at least 1".into(),
                ));
            }
        }
        if let Some(c) = &self.control {
            if c.point.is_some() == c.set.is_some() {
                return Err((
                    "structure.control".into(),
                    "expected one of `point = [x, y, z]` or `set` (a set of one node)".into(),
                ));
            }
            if !(c.value.is_finite() && c.value != 0.0) {
                return Err((
                    "structure.control.value".into(),
                    format!("expected a finite nonzero displacement, got {}", c.value),
                ));
            }
        }
        Ok(())
    }
}
