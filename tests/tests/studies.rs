//! Every coupled-system study passes all its checks against the sources (see
//! `system_tests::studies`). Needs the FMUs (`cargo xtask build-fmus`).

fn check(id: &str) {
    match system_tests::studies::run(id) {
        Ok(report) => report.assert_passed(),
        Err(e) => panic!("study {id}: {e}"),
    }
}

#[test]
fn steering_gear() {
    check("steering_gear");
}

#[test]
fn rrs() {
    check("rrs");
}

#[test]
fn path_control() {
    check("path_control");
}

#[test]
fn dp_observer() {
    check("dp_observer");
}

#[test]
fn dgps_trial() {
    check("dgps_trial");
}

#[test]
fn autopilot() {
    check("autopilot");
}

#[test]
fn path_estimation() {
    check("path_estimation");
}

#[test]
fn container_ship_seaway() {
    check("container_ship_seaway");
}

#[test]
fn loop_analysis() {
    check("loop_analysis");
}
