use compensator::dynamics::{Scheme, TwinConfig};
use compensator_cli::dynamics::{Precision, simulate};
use compensator_reference::dynamics::{self as reference, Method, Profile};
use host_tests::random::Rng;
use host_tests::survey::{designs, settle_time, steps};
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let want: usize = a[1].parse().unwrap();
    let kind: usize = a[2].parse().unwrap();
    let sub: u8 = a[3].parse().unwrap();
    let every: usize = a[4].parse().unwrap();
    let mut rng = Rng::new(7);
    let ds = designs(want + 1, 0xD5);
    let mut st = None;
    for (i, raw) in ds.iter().enumerate() {
        let s = steps(raw, &mut rng);
        if i == want {
            st = Some(s[kind]);
        }
    }
    let st = st.unwrap();
    let raw = ds[want];
    let p = compensator::Params::<f64>::new(&raw).unwrap();
    println!(
        "{st:?} stroke {} dp {} settle {}",
        raw.core.stroke,
        raw.core.pressure_drop,
        settle_time(&raw, &st)
    );
    for t in [st.from, st.to] {
        let l = compensator::dynamics::linear::linearise(&p, t).unwrap();
        println!(
            "eig {t}: {:?}",
            l.eigenvalues.iter().map(|e| (e.re, e.im)).collect::<Vec<_>>()
        );
        let e = host_tests::reference::equilibrium(&raw.core, t);
        println!("eq {t}: x {} pa {} pb {}", e.x, e.p_a, e.p_b);
    }
    let ticks: usize = a
        .get(5)
        .map(|s| s.parse().unwrap())
        .unwrap_or((settle_time(&raw, &st) / 1e-3).round() as usize);
    let prof = Profile::Step {
        from: st.from,
        to: st.to,
    };
    let tr = reference::simulate(&raw.core, prof, ticks as f64 * 1e-3, 1e-3, Method::Radau5, 1e-10).unwrap();
    println!("events {:?}", &tr.events[..tr.events.len().min(10)]);
    let cfg = TwinConfig {
        scheme: Scheme::Sdirk3,
        substeps: sub,
        ..TwinConfig::SHIPPED
    };
    let r = simulate(&raw, Precision::F64, cfg, &prof, ticks).unwrap();
    for k in (0..=ticks).step_by(every) {
        let s = &r.state[k];
        let y = &tr.state[k];
        println!(
            "{k} ref x {:.6e} v {:.4e} pa {:.1} pb {:.1} | twin x {:.6e} v {:.4e} pa {:.1} pb {:.1} | dx {:.2e}",
            y[0],
            y[1],
            y[2],
            y[3],
            s.x,
            s.v,
            s.p_a,
            s.p_b,
            s.x - y[0]
        );
    }
}
