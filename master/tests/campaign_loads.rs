//! A campaign loads each distinct FMU library once per process, however many runs and
//! instances it makes (alone in its test binary: the load counter is process-wide).

use shipsim::campaign::{execute, Campaign, CampaignOptions, CampaignSpec};
use std::path::Path;

#[test]
fn each_fmu_library_is_loaded_once_for_all_runs() {
    let dir = tempfile::tempdir().unwrap();
    let system = Path::new(env!("CARGO_MANIFEST_DIR")).join("../systems/rrs.toml");
    let text = format!(
        "system = \"{}\"\nstop_time = 2.0\n[replications]\ncount = 12\nseeds = [\"waves.seed\"]\n\
         [[kpis]]\nname = \"r\"\nvariable = \"ship.roll\"\nstat = \"mean\"\n",
        system.display()
    );
    let file = dir.path().join("c.toml");
    std::fs::write(&file, text).unwrap();
    let c = Campaign::from_spec(CampaignSpec::load(&file).unwrap()).unwrap();
    let before = shipsim::fmu::load_count();
    let opts = CampaignOptions {
        jobs: Some(2),
        output: dir.path().join("out"),
        ..Default::default()
    };
    let outcome = execute::run(&c, &opts).unwrap();
    assert_eq!((outcome.ran, outcome.failed), (12, 0));
    // 12 runs x 7 instances, of 7 distinct FMU files: 7 loads.
    assert_eq!(c.system.instances.len(), 7);
    assert_eq!(shipsim::fmu::load_count() - before, 7);
}
