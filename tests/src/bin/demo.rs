//! `cargo xtask demo`: the built-in default system, rudder roll stabilization (systems/rrs.toml),
//! run through the shipsim master with RRS off (course keeping only) and on, same seed. Prints
//! the roll, heading and rudder statistics and writes the CSVs and a plot to target/demo/.

use system_tests::studies::rrs;
use system_tests::study::Env;

fn main() {
    let env = match Env::new("demo") {
        Ok(e) => e,
        Err(e) => {
            eprintln!("demo: {e}");
            std::process::exit(1);
        }
    };
    let (off, on, fig) = match rrs::demo(&env) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("demo: {e}");
            std::process::exit(1);
        }
    };
    println!();
    println!("Rudder roll stabilization, van der Klugt (1987): RRS ship (Table 2.4) at 11 m/s in beam seas,");
    println!("beam wind with gusts, 15 deg/s steering gear, roll and yaw filters, RRS autopilot with AGC and");
    println!("criterion adaptation.");
    println!("Statistics over 200-1200 s; the open-loop roll is tuned to Table 7.1's 16 deg^2.");
    println!();
    println!("{:<28} {:>12} {:>12}", "", "RRS off", "RRS on");
    println!(
        "{:<28} {:>12.2} {:>12.2}",
        "roll variance [deg^2]", off.roll_var, on.roll_var
    );
    println!(
        "{:<28} {:>12.3} {:>12.3}",
        "heading variance [deg^2]", off.heading_var, on.heading_var
    );
    println!(
        "{:<28} {:>12.3} {:>12.2}",
        "rudder variance [deg^2]", off.rudder_var, on.rudder_var
    );
    println!(
        "{:<28} {:>12.1} {:>12.1}",
        "rate-limited time [s]", off.rate_saturated, on.rate_saturated
    );
    println!();
    println!(
        "roll reduction 100(1 - var_on/var_off) = {:.1} %   (thesis, Table 7.1: 78 %)",
        100.0 * (1.0 - on.roll_var / off.roll_var)
    );
    println!();
    println!("CSV:  {}", env.out_dir.join("exp1_off.csv").display());
    println!("      {}", env.out_dir.join("exp1_on.csv").display());
    println!("plot: {}", fig.display());
}
