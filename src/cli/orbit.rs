//! The `--orbit` value of `fly`: `CX,CY,CZ,RADIUS,HEIGHT[,TURNS]`.

use glam::DVec3;

use alpenglow::{Orbit, DEFAULT_START_ANGLE_DEG};

use super::errors::describe;

/// Parses `CX,CY,CZ,RADIUS,HEIGHT[,TURNS]` (TURNS default 1) into an orbit
/// starting at [`DEFAULT_START_ANGLE_DEG`]; errors name `--orbit` and the value.
pub fn parse_orbit(s: &str) -> Result<Orbit, String> {
    let usage = "CX,CY,CZ,RADIUS,HEIGHT[,TURNS]";
    let numbers = s
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<Vec<_>, _>>()
        .map_err(|_| format!("--orbit '{s}' is not {usage} (comma-separated numbers)"))?;
    let (centre, radius, height, turns) = match numbers.as_slice() {
        &[x, y, z, r, h] => (DVec3::new(x, y, z), r, h, 1.0),
        &[x, y, z, r, h, n] => (DVec3::new(x, y, z), r, h, n),
        other => return Err(format!("--orbit '{s}' has {} numbers; expected {usage}", other.len())),
    };
    let orbit = Orbit {
        centre,
        radius,
        height,
        turns,
        start_angle_deg: DEFAULT_START_ANGLE_DEG,
    };
    orbit
        .validate()
        .map_err(|e| format!("--orbit '{s}': {}", describe(&e)))?;
    Ok(orbit)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_orbit_reads_five_or_six_numbers() {
        let orbit = parse_orbit("5120, 5120, 200, 3000, 900").unwrap();
        assert_eq!(
            orbit,
            Orbit {
                centre: DVec3::new(5120.0, 5120.0, 200.0),
                radius: 3000.0,
                height: 900.0,
                turns: 1.0,
                start_angle_deg: DEFAULT_START_ANGLE_DEG,
            }
        );
        assert_eq!(parse_orbit("0,0,0,10,5,0.5").unwrap().turns, 0.5);
        assert_eq!(parse_orbit("0,0,-3,10,5").unwrap().centre.z, -3.0);
    }

    #[test]
    fn parse_orbit_rejects_bad_values() {
        for s in [
            "",
            "1,2,3,4",
            "1,2,3,4,5,6,7",
            "1,2,x,4,5",
            "1,2,3,0,5",
            "1,2,3,-1,5",
            "1,2,3,4,inf",
        ] {
            let e = parse_orbit(s).unwrap_err();
            assert!(e.starts_with(&format!("--orbit '{s}'")), "{e}");
            assert!(!e.contains("invalid orbit"), "the library's name leaks: {e}");
        }
        let e = parse_orbit("1,2,3,0,5").unwrap_err();
        assert_eq!(e, "--orbit '1,2,3,0,5': invalid --orbit: radius 0 must be positive");
    }
}
