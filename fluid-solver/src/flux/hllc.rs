//! Toro's HLLC flux (Toro, Spruce & Speares, Shock Waves 4, 1994; Toro, *Riemann Solvers and
//! Numerical Methods for Fluid Dynamics*, 3rd ed., §10.4) with Einfeldt's wave-speed bounds
//! `S_l = min(u_nl - c_l, ũ_n - c̃)`, `S_r = max(u_nr + c_r, ũ_n + c̃)` from the Roe averages,
//! which keep it positively conservative (Batten et al., SIAM J. Sci. Comput. 18, 1997).
//! The star states use only mass, momentum and energy jump conditions, so one formula serves all
//! three EOS (for Tait the star densities are approximate; the flux stays conservative).

use super::{flux_of, roe_average, unit};
use crate::eos::Eos;

/// HLLC flux integrated over the facet with area normal `n`.
#[inline(always)]
pub fn hllc(eos: &Eos, wl: &[f64; 5], wr: &[f64; 5], n: &[f64; 3]) -> [f64; 5] {
    let (nh, area) = unit(n);
    let ql = eos.prim_to_cons(wl);
    let qr = eos.prim_to_cons(wr);
    let avg = roe_average(eos, wl, &ql, wr, &qr);
    let unl = wl[1] * nh[0] + wl[2] * nh[1] + wl[3] * nh[2];
    let unr = wr[1] * nh[0] + wr[2] * nh[1] + wr[3] * nh[2];
    let un = avg.u[0] * nh[0] + avg.u[1] * nh[1] + avg.u[2] * nh[2];
    let sl = (unl - eos.sound_speed(wl[0], wl[4])).min(un - avg.c);
    let sr = (unr + eos.sound_speed(wr[0], wr[4])).max(un + avg.c);
    let mut f = if sl >= 0.0 {
        flux_of(wl, &ql, &nh)
    } else if sr <= 0.0 {
        flux_of(wr, &qr, &nh)
    } else {
        // Contact speed from equal star pressures (Toro Eq. 10.37).
        let ml = wl[0] * (sl - unl);
        let mr = wr[0] * (sr - unr);
        let s_star = (wr[4] - wl[4] + ml * unl - mr * unr) / (ml - mr);
        let (w, q, s, unk) = if s_star >= 0.0 { (wl, &ql, sl, unl) } else { (wr, &qr, sr, unr) };
        // F*_k = f_k + S_k (Q*_k - Q_k) (Toro Eq. 10.38-10.39).
        let fk = flux_of(w, q, &nh);
        let m = w[0] * (s - unk);
        let rho_star = m / (s - s_star);
        let du = s_star - unk;
        let e_star = rho_star * (q[4] / w[0] + du * (s_star + w[4] / m));
        let q_star = [
            rho_star,
            rho_star * (w[1] + du * nh[0]),
            rho_star * (w[2] + du * nh[1]),
            rho_star * (w[3] + du * nh[2]),
            e_star,
        ];
        let mut f = [0.0; 5];
        for k in 0..5 {
            f[k] = fk[k] + s * (q_star[k] - q[k]);
        }
        f
    };
    for fk in &mut f {
        *fk *= area;
    }
    f
}
