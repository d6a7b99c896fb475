//! Glue shared by the controller FMUs (`fmu-lqr`, `fmu-tsd`) between the
//! controller interface ([`flight_mission`]) and the FMI export layer
//! ([`fmi2_export`]): the held output in FMU states and the controller's
//! notices on the FMI logger. Knows neither controller.

use flight_mission::{ControllerOutput, Notice};
use fmi2_export::{Logger, StateError, StateReader, StateWriter};

/// Append the held output (or its absence) to an FMU state.
pub fn write_held(w: &mut StateWriter, held: &Option<ControllerOutput>) {
    w.bool(held.is_some());
    if let Some(out) = held {
        out.save(&mut |x| w.f64(x));
    }
}

/// Read back what [`write_held`] wrote.
pub fn read_held(r: &mut StateReader<'_>) -> Result<Option<ControllerOutput>, StateError> {
    if !r.bool()? {
        return Ok(None);
    }
    let mut saved = [0.0; ControllerOutput::SAVED_LEN];
    for x in saved.iter_mut() {
        *x = r.f64()?;
    }
    let mut it = saved.into_iter();
    ControllerOutput::restore(&mut || it.next())
        .map(Some)
        .ok_or_else(|| StateError::invalid("held controller output: phase out of range"))
}

/// Log a controller's notice as a warning; `was_saturated` (the previous
/// sample's saturation) keeps a lasting saturation to one message.
/// Returns whether this sample is saturated.
pub fn log_notice(log: &mut Logger<'_>, t: f64, notice: Option<Notice>, was_saturated: bool) -> bool {
    match notice {
        Some(Notice::GainFallback(why)) => log.warning(format_args!(
            "t = {t} s: gain computation failed ({why}); using the last good gains"
        )),
        Some(Notice::Saturated(name)) if !was_saturated => log.warning(format_args!(
            "t = {t} s: {name} saturated (not logged again until it ends)"
        )),
        _ => {}
    }
    matches!(notice, Some(Notice::Saturated(_)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use flight_mission::{Command, Diagnostics, Phase};

    #[test]
    fn held_output_round_trips_and_rejects_corruption() {
        let out = ControllerOutput {
            command: Command {
                thrust: 12.0,
                rudder: 0.1,
                ..Default::default()
            },
            diagnostics: Diagnostics {
                ref_pos_ned: flight_mission::nalgebra::Vector3::new(1.0, 2.0, 3.0),
                ref_airspeed: 25.0,
                phase: Phase::TransitionToVertical,
                pos_error: 0.3,
            },
            notice: None,
        };
        for held in [None, Some(out)] {
            let mut w = StateWriter::new();
            write_held(&mut w, &held);
            let bytes = w.into_bytes();
            let mut r = StateReader::new(&bytes);
            assert_eq!(read_held(&mut r).unwrap(), held);
            r.finish().unwrap();
            // Every truncation is an error, never a panic.
            for n in 0..bytes.len() {
                assert!(read_held(&mut StateReader::new(&bytes[..n])).is_err(), "{n}");
            }
        }
        let mut w = StateWriter::new();
        let mut bad = out;
        bad.diagnostics.phase = Phase::Vertical1;
        write_held(&mut w, &Some(bad));
        let mut bytes = w.into_bytes();
        let phase_at = bytes.len() - 8;
        bytes[phase_at..].copy_from_slice(&9.0f64.to_le_bytes());
        assert!(read_held(&mut StateReader::new(&bytes)).is_err());
    }

    #[test]
    fn lasting_saturation_is_logged_once() {
        let mut log = Logger::null();
        let s = log_notice(&mut log, 0.0, Some(Notice::Saturated("thrust_cmd")), false);
        assert!(s);
        assert!(log_notice(&mut log, 0.02, Some(Notice::Saturated("thrust_cmd")), s));
        assert!(!log_notice(&mut log, 0.04, None, true));
    }
}
