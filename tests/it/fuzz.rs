//! Random input to the parsers a user reaches: the config file, `--set`,
//! `--set-range` and the schedule reader. Whatever comes in, they return a
//! value or an error, never panic; and an error is a message, not empty.
//! Inputs are mutations of valid ones (so the parsers get past their first
//! line) and random strings from the characters the formats use. A fixed
//! seed keeps failures reproducible; the failing input is printed.

use crate::util;

use catflip::Config;
use catflip::design::plan::Schedule;
use catflip::sweep::SweepSpec;
use util::config_text;

/// xorshift64*: no dependency, repeatable.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn pick<'a>(&mut self, xs: &[&'a str]) -> &'a str {
        xs[self.below(xs.len())]
    }
}

const PIECES: &[&str] = &[
    "=",
    ".",
    ",",
    ":",
    "[",
    "]",
    "{",
    "}",
    "\"",
    "'",
    "\n",
    " ",
    "#",
    "-",
    "+",
    "e",
    "E",
    "0",
    "1",
    "9",
    "1e308",
    "-1e308",
    "1e-320",
    "nan",
    "inf",
    "-inf",
    "NaN",
    "0.5",
    "-7",
    "99999999999999999999",
    "cat",
    "fall",
    "mass",
    "height",
    "split",
    "analytic",
    "limits",
    "max_torque",
    "name",
    "joint",
    "universal",
    "no-twist",
    "fold",
    "twist",
    "unfold",
    "t_s",
    "phase",
    "tau1_nm",
    "\u{0}",
    "é",
    "\r",
    "true",
    "x",
    "[[",
    "]]",
    "[cat]",
    "=[",
    "1:2:3",
    "0:0:0",
    "::",
    // issue 31: the keys and sections whose ranges bound the work
    "[cat.front]",
    "[limits]",
    "[simulate]",
    "[phased]",
    "[free]",
    "[design]",
    "gravity",
    "radius",
    "length",
    "no_load_speed",
    "max_speed",
    "max_bend_deg",
    "theta_deg",
    "pd_bandwidth_hz",
    "max_iterations",
    "bend_tol_deg",
    "samples_per_phase",
    "1e9",
    "4414",
    "179.99999",
    "0.785",
    "1e-9",
    "30",
];

/// Random edits of `base`: insert, delete, replace or duplicate pieces.
fn mutate(rng: &mut Rng, base: &str) -> String {
    let mut s: Vec<char> = base.chars().collect();
    for _ in 0..1 + rng.below(6) {
        let at = if s.is_empty() {
            0
        } else {
            rng.below(s.len() + 1)
        };
        match rng.below(4) {
            0 => {
                let p: Vec<char> = rng.pick(PIECES).chars().collect();
                s.splice(at..at, p);
            }
            1 => {
                let end = (at + 1 + rng.below(20)).min(s.len());
                if at < end {
                    s.drain(at..end);
                }
            }
            2 if at < s.len() => {
                let p: Vec<char> = rng.pick(PIECES).chars().collect();
                let end = (at + p.len()).min(s.len());
                s.splice(at..end, p);
            }
            _ => {
                let end = (at + rng.below(40)).min(s.len());
                let chunk: Vec<char> = s[at..end].to_vec();
                s.splice(at..at, chunk);
            }
        }
    }
    s.into_iter().collect()
}

fn random_text(rng: &mut Rng) -> String {
    (0..rng.below(30)).map(|_| rng.pick(PIECES)).collect()
}

/// Runs `f`, and on a panic reports the input that caused it.
fn no_panic<T>(what: &str, input: &str, f: impl FnOnce() -> catflip::Result<T>) {
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
    match r {
        Ok(Ok(_)) => {}
        Ok(Err(e)) => assert!(
            !e.to_string().trim().is_empty(),
            "{what}: empty error for {input:?}"
        ),
        Err(_) => panic!("{what} panicked on {input:?}"),
    }
}

#[test]
fn config_file_and_set_parsers_never_panic() {
    let mut rng = Rng(0xC0FF_EE00_1234_5678);
    let base = config_text("seed");
    let keys = [
        "cat.mass",
        "cat.joint",
        "fall.height",
        "fall.margin",
        "analytic.split",
        "analytic.theta_deg",
        "limits.max_torque",
        "limits.norm",
        "simulate.samples_per_phase",
        "phased.nodes",
        "free.nodes",
        "fall.gravity",
        "cat.radius",
        "cat.length",
        "cat.front.mass",
        "cat.front.length",
        "cat.front.radius",
        "limits.no_load_speed",
        "limits.max_speed",
        "limits.max_bend_deg",
        "simulate.rtol",
        "simulate.pd_bandwidth_hz",
        "simulate.pd_damping",
        "phased.bend_tol_deg",
        "free.max_iterations",
        "design.objective",
        "name",
        "cat",
        "x.y.z",
        "",
    ];
    for i in 0..10_000 {
        let text = if i % 5 == 0 {
            random_text(&mut rng)
        } else {
            mutate(&mut rng, &base)
        };
        let overrides: Vec<String> = (0..rng.below(3))
            .map(|_| {
                let arg = format!("{}={}", rng.pick(&keys), random_text(&mut rng));
                if rng.below(2) == 0 {
                    mutate(&mut rng, &arg)
                } else {
                    arg
                }
            })
            .collect();
        let input = format!("{text}\n--set {overrides:?}");
        no_panic("Config::from_toml", &input, || {
            let cfg = Config::from_toml(&text, "fuzz.toml", &overrides)?;
            // what is accepted implies bounded work and finite numbers
            let t = cfg.fall_time();
            assert!(
                (catflip::config::ranges::MIN_FALL_TIME_S
                    ..=catflip::config::ranges::MAX_FALL_TIME_S)
                    .contains(&t),
                "{input:?}: fall time {t}"
            );
            let cf = catflip::design::analytic::closed_forms(&cfg.design_spec());
            assert!(
                cf.twist_rad.is_finite() && cf.seed_torque_estimate_nm.is_finite(),
                "{input:?}: {cf:?}"
            );
            for s in cfg.slips() {
                assert!(!s.message.is_empty());
            }
            Ok(())
        });
    }
}

#[test]
fn set_range_parser_never_panics_and_accepts_only_what_it_can_run() {
    let mut rng = Rng(0x5EED_0000_0000_0001);
    let base = "fall.height=0.5:10:40";
    for i in 0..20_000 {
        let s = if i % 3 == 0 {
            random_text(&mut rng)
        } else {
            mutate(&mut rng, base)
        };
        let r = std::panic::catch_unwind(|| s.parse::<SweepSpec>());
        match r {
            Err(_) => panic!("SweepSpec::from_str panicked on {s:?}"),
            Ok(Ok(spec)) => {
                // whatever parses is bounded and finite
                assert!(
                    spec.count >= 1 && spec.count <= catflip::sweep::MAX_POINTS,
                    "{s:?}"
                );
                assert!(spec.values().iter().all(|v| v.is_finite()), "{s:?}");
            }
            Ok(Err(e)) => assert!(e.to_string().contains("--set-range"), "{s:?}: {e}"),
        }
    }
}

#[test]
fn schedule_reader_never_panics() {
    let mut rng = Rng(0xFEED_FACE_CAFE_BEEF);
    let cfg = Config::from_toml(&config_text("seed"), "seed", &[]).unwrap();
    // a short valid schedule of the seed's fall
    let plan = catflip::design::analytic::analytic_plan(&cfg.design_spec());
    let base = Schedule::sample(&cfg.cat(), &plan, 4).to_csv();
    assert!(
        catflip::verify::simulate::read_schedule(&cfg.design_spec(), &cfg.name, &base, "base")
            .is_ok()
    );
    let base_json = Schedule::sample(&cfg.cat(), &plan, 4).to_json();
    assert!(
        catflip::verify::simulate::read_schedule(&cfg.design_spec(), &cfg.name, &base_json, "base")
            .is_ok()
    );
    for i in 0..10_000 {
        let text = if i % 7 == 0 {
            random_text(&mut rng)
        } else {
            mutate(&mut rng, &base)
        };
        no_panic("Schedule::from_csv", &text, || {
            Schedule::from_csv(&text, "fuzz.csv")
        });
        // the JSON form of the same rows (issue 31), mutated alike
        let json = if i % 7 == 0 {
            random_text(&mut rng)
        } else {
            mutate(&mut rng, &base_json)
        };
        no_panic("Schedule::from_json", &json, || {
            Schedule::from_json(&json, "fuzz.schedule.json")
        });
        no_panic("read_schedule", &text, || {
            let s = catflip::verify::simulate::read_schedule(
                &cfg.design_spec(),
                &cfg.name,
                &text,
                "fuzz.csv",
            )?;
            // what is accepted is usable as a plan over the whole fall
            let b = catflip::design::plan::ShapePlan::phase_bounds(&s);
            assert!(b.windows(2).all(|w| w[0] <= w[1]), "{b:?}");
            let _ = catflip::design::plan::ShapePlan::state(&s, b[3] * 0.5);
            Ok(())
        });
    }
}
