use compensator::dynamics::{Scheme, TwinConfig};
use compensator_cli::dynamics::{Precision, simulate};
use compensator_reference::dynamics::{self as reference, Method, Profile};
use host_tests::random::Rng;
use host_tests::survey::{designs, steps};
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let want: usize = a[1].parse().unwrap();
    let kind: usize = a[2].parse().unwrap();
    let sub: u8 = a[3].parse().unwrap();
    let ticks: usize = a[4].parse().unwrap();
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
    println!("{st:?} stroke {}", raw.core.stroke);
    let prof = Profile::Step {
        from: st.from,
        to: st.to,
    };
    let rt: f64 = a.get(5).map(|s| s.parse().unwrap()).unwrap_or(1e-10);
    let dt: f64 = a.get(6).map(|s| s.parse().unwrap()).unwrap_or(1e-3);
    let tr = reference::simulate(&raw.core, prof, ticks as f64 * dt, dt, Method::Radau5, rt).unwrap();
    println!("events {:?}", tr.events);
    let cfg = TwinConfig {
        scheme: Scheme::Sdirk3,
        substeps: sub,
        tick: dt,
    };
    let r = simulate(&raw, Precision::F64, cfg, &prof, ticks).unwrap();
    for k in 0..=ticks {
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
#[allow(dead_code)]
fn unused() {}
