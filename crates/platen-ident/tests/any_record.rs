//! The any-record method on independent lab-format records (see `lab/mod.rs`).

mod lab;

use platen_ident::{identify_records, IdentifiedKey, RecordSettings};

#[test]
fn explore() {
    let settings = RecordSettings::default().build().unwrap();
    for (file, storeys) in [("eq-lab.csv", 0), ("wn-lab.csv", 0), ("wn-low-lab.csv", 0), ("eq-two-storey-lab.csv", 2)] {
        let rec = lab::lab_record(file, storeys);
        let t0 = std::time::Instant::now();
        let id = identify_records(&[rec], &settings).unwrap();
        println!("{file}: {:?}", t0.elapsed());
        for (key, p) in id.equation_error.parameters.iter() {
            let truth = lab::true_value(key);
            let oe = id.output_error.as_ref().map(|o| o.parameters.get(key).clone());
            println!("  {:28} EE {:?} truth {truth} OE {:?}", key.name(), p.estimate().map(|e| (e.value, e.std_error, e.value/truth-1.0)), oe.and_then(|p| p.estimate().map(|e| (e.value, e.std_error, e.value/truth-1.0))));
        }
        println!("  ee rms {} pts {} bw {} crit {}", id.equation_error.rms_residual_n, id.equation_error.points, id.equation_error.uncertainty.bandwidth_samples, id.equation_error.uncertainty.critical_value);
        if let Some(o) = &id.output_error { println!("  oe it {} conv {} sims {} rms u {:?} a {:?}", o.iterations, o.converged, o.simulations, o.rms_u_m, o.rms_a_m_s2); }
        for w in &id.warnings { println!("  W: {w}"); }
        let _ = IdentifiedKey::ALL;
    }
}
