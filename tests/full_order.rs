//! Full-order γ_opt on the shipped plants against SLICOT SB10AD fixtures and the plant files'
//! `check` values, plus hand cases with closed-form γ_opt.
use hinfix::lti::{full_order_gamma, full_order_gamma_with, FullOrderOptions, Plant, Regularisation};

fn plant(name: &str) -> Plant {
    Plant::load(format!("{}/plants/{name}.json", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

#[test]
#[ignore]
fn print_all() {
    for name in ["HE1", "Enns", "AC8", "REA2", "HF1", "AC10", "BDT2", "CM4"] {
        let t = std::time::Instant::now();
        let r = full_order_gamma(&plant(name));
        println!("{name}: {:.2}s", t.elapsed().as_secs_f64());
        match r {
            Ok(r) => println!("{r}"),
            Err(e) => println!("error {e}"),
        }
    }
}
