//! Replays a `twin` input (the segments as the target runs them), then
//! holds the last temperature the twin took for SECONDS and prints, every
//! 50 ms, how far the state is from the closed form (strokes, dp): what
//! tells a twin that is slow to arrive from one that settles elsewhere.
//!
//! `cargo run --release --manifest-path fuzz/Cargo.toml --example twin_hold -- FILE [SECONDS]`

use compensator::dynamics::Twin;
use compensator::equilibrium::equilibrium;
use compensator::scalar::Fixed;
use compensator::{Float, Params, Real};
use compensator_fuzz::{check, twin};

fn hold<F: Float, T: Real>(input: &twin::Input, p: &Params<F>, seconds: f64) {
    let Ok(mut tw) = Twin::<F, T>::new(p, input.config, F::from_f64(input.start)) else {
        println!("the twin refuses the start");
        return;
    };
    let mut held = F::from_f64(input.start);
    let mut ticks = 0u32;
    for &(t, n) in &input.segments {
        if tw.set_temperature(F::from_f64(t)).is_ok() {
            held = F::from_f64(t);
        }
        for _ in 0..n {
            if ticks >= twin::SEGMENT_TICKS {
                break;
            }
            ticks += 1;
            if let Err(e) = tw.tick() {
                println!("tick {ticks}: {e:?}");
                return;
            }
        }
    }
    let eq = equilibrium(p, held).expect("the held temperature's closed form");
    println!("held at {held:?} C; closed form {eq:?}");
    let per = (0.05 / input.config.tick).round() as u32;
    for k in 0..=((seconds / input.config.tick) as u32) {
        if k % per == 0 {
            let s = tw.state();
            println!(
                "{:7.3} s: off {:.3e}  x {:?} v {:?} p_a {:?} p_b {:?}",
                f64::from(k) * input.config.tick,
                check::off_rest(&s, &eq, p),
                s.x,
                s.v,
                s.p_a,
                s.p_b
            );
        }
        if let Err(e) = tw.tick() {
            println!("hold tick {k}: {e:?}");
            return;
        }
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let file = args.next().expect("usage: twin_hold FILE [SECONDS]");
    let seconds: f64 = args.next().map_or(5.0, |s| s.parse().expect("seconds"));
    let input = twin::decode(&std::fs::read(file).expect("the input file"));
    println!("{:?} {:?} scalar {}", input.design, input.config, input.scalar);
    println!("{:?}", input.raw.core);
    match input.scalar {
        0 => hold::<f32, f32>(&input, &Params::new(&input.raw).unwrap(), seconds),
        1 => hold::<f64, f64>(&input, &Params::new(&input.raw).unwrap(), seconds),
        _ => hold::<f32, Fixed>(&input, &Params::new(&input.raw).unwrap(), seconds),
    }
}
