//! Trial: the monitor on a degraded paper preset.
use compensator::Params;
use compensator::estimator::{Estimator, EstimatorConfig, Flags};
use compensator::monitor::{MonitorSettings, Quantity};
use compensator_reference::statics::equilibrium;
use host_tests::random::Rng;
use host_tests::repo_root;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let q = match args.first().map(String::as_str) {
        Some("x") => Quantity::Displacement,
        Some("dp") => Quantity::Difference,
        Some("pb") => Quantity::ChamberB,
        _ => Quantity::ChamberA,
    };
    let fault: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(0);
    let mut raw = compensator_cli::load(&repo_root().join("presets/paper.toml")).unwrap();
    raw.probe.time_constant = 0.01;
    raw.probe.well_time_constant = 0.0;
    let p = Params::<f32>::new(&raw).unwrap();
    let cfg = EstimatorConfig::new(&raw).unwrap();
    let (sd_noise, sd_acc) = if q == Quantity::Displacement {
        (1e-3 * raw.core.stroke, 1e-3 * raw.core.stroke)
    } else {
        (100.0, 250.0)
    };
    let settings = MonitorSettings {
        quantity: q,
        sd_noise: sd_noise as f32,
        sd_accuracy: sd_acc as f32,
        sample_period: 0.01,
    };
    let mut est = Estimator::new(&p, cfg, 30.0).unwrap().with_monitor(settings).unwrap();
    let mut bad = raw.core;
    match fault {
        1 => bad.laminar_diameter *= 0.8f64.powf(0.25),
        2 => bad.spring_rate *= 0.9,
        3 => bad.preload *= 0.8,
        _ => {}
    }
    let mut rng = Rng::new(7);
    let temp = |t: f64| {
        if t < 300.0 {
            30.0 + 0.1 * t
        } else {
            if t < 400.0 {
                60.0
            } else {
                (60.0 - 0.1 * (t - 400.0)).max(35.0)
            }
        }
    };
    let t_fault = 400.0;
    let dt = 1e-3;
    let mut x_held = f64::NAN;
    let mut first = None;
    let mut seen = Flags::empty();
    for k in 0..900_000u64 {
        let t = k as f64 * dt;
        let tt = temp(t);
        if k % 20 == 0 {
            est.tick(Ok(Some(tt as f32)));
        } else {
            est.tick(Ok(None));
        }
        if k % 10 == 0 {
            let core = if t >= t_fault { &bad } else { &raw.core };
            let pt = equilibrium(core, tt);
            let _ = &mut x_held;
            let y = match q {
                Quantity::ChamberA => pt.p_a,
                Quantity::ChamberB => pt.p_b,
                Quantity::Difference => pt.p_b - pt.p_a,
                Quantity::Displacement => pt.x,
            };
            let n = (rng.unit() + rng.unit() + rng.unit() + rng.unit() - 2.0) * (3.0f64).sqrt();
            est.offer_second(Ok((y + n * sd_noise) as f32));
        }
        let now = Flags(est.health().flags.0 & !Flags::INNOVATION_REJECTED.0);
        if now != seen {
            println!("  t {t:8.3} T {tt:6.2} flags {:?}", now.names().collect::<Vec<_>>());
            seen = now;
        }
        if std::env::var("RESID").is_ok() && k % 50_000 == 7 {
            let e = est.tick(Ok(None));
            let pt = equilibrium(&raw.core, tt);
            println!(
                "resid t {t:.1} T {tt:.2} est.T {:.3} twin x {:.4e} ref x {:.4e} dx {:.2e} p_a {:.1} ref {:.1}",
                e.temperature,
                e.x,
                pt.x,
                e.x as f64 - pt.x,
                e.p_a,
                pt.p_a
            );
        }
        if k % 100_000 == 1
            || (first.is_none() && !est.health().flags.is_empty() && est.health().flags != Flags::INNOVATION_REJECTED)
        {
            let h = est.health();
            if first.is_none() && !(h.flags.0 & !Flags::INNOVATION_REJECTED.0 == 0) {
                first = Some(t);
            }
            println!(
                "t {t:7.2} T {tt:6.2} div {:.4}±{:.4} spr {:.4}±{:.4} off {:.3e}±{:.2e} fr {:.3} z {:6.2} g {:5.1} rej {} {:?}",
                h.divider,
                h.sd_divider,
                h.spring,
                h.sd_spring,
                h.offset,
                h.sd_offset,
                h.friction,
                h.innovation,
                h.cusum,
                h.rejected,
                h.flags.names().collect::<Vec<_>>()
            );
        }
    }
    println!("first flag at {first:?} (fault at {t_fault})");
}

#[allow(dead_code)]
fn check() {}
