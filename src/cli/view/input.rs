//! The viewer's input: the keys it knows, what a window or a script
//! (`--input EVENTS`) sends, and the state held between frames.
//!
//! An EVENTS file has one event per line, `FRAME EVENT…`, applied before
//! frame FRAME (0-based) is rendered; `#` starts a comment:
//!
//! ```text
//! 0 key W down      # hold W (names: W A S D Q E Space C Shift V G F1 F11 F12
//! 6 key W up        #   Up Down Left Right Escape)
//! 7 mouse 40 -10    # mouse look: moved 40 px right, 10 px up (button held)
//! 8 wheel 2         # two notches up: faster
//! 9 key F12         # a press and release
//! 10 resize 640 360 # the window asks for a new size
//! ```

use std::path::Path;

use anyhow::{bail, Context as _, Result};

use super::fly_camera::Motion;

/// The keys the viewer reacts to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Key {
    W,
    A,
    S,
    D,
    Q,
    E,
    Space,
    C,
    Shift,
    /// Cycles the shown view of a rig.
    V,
    /// Cycles the presented image: colour, then each AOV's debug view.
    G,
    /// Sun elevation up/down, azimuth left/right.
    Up,
    Down,
    Left,
    Right,
    /// Hides or shows the overlay.
    F1,
    /// Capture: RenderDoc's next frame.
    F11,
    /// Capture: PNG, EXR, profile and trace of the frame on screen.
    F12,
    Escape,
}

const NAMES: [(&str, Key); 19] = [
    ("W", Key::W),
    ("A", Key::A),
    ("S", Key::S),
    ("D", Key::D),
    ("Q", Key::Q),
    ("E", Key::E),
    ("Space", Key::Space),
    ("C", Key::C),
    ("Shift", Key::Shift),
    ("V", Key::V),
    ("G", Key::G),
    ("Up", Key::Up),
    ("Down", Key::Down),
    ("Left", Key::Left),
    ("Right", Key::Right),
    ("F1", Key::F1),
    ("F11", Key::F11),
    ("F12", Key::F12),
    ("Escape", Key::Escape),
];

impl Key {
    fn parse(name: &str) -> Option<Key> {
        NAMES
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, k)| *k)
    }

    /// The key of a winit key code, if the viewer knows it.
    pub fn from_winit(code: winit::keyboard::KeyCode) -> Option<Key> {
        use winit::keyboard::KeyCode as K;
        Some(match code {
            K::KeyW => Key::W,
            K::KeyA => Key::A,
            K::KeyS => Key::S,
            K::KeyD => Key::D,
            K::KeyQ => Key::Q,
            K::KeyE => Key::E,
            K::Space => Key::Space,
            K::KeyC | K::ControlLeft => Key::C,
            K::ShiftLeft | K::ShiftRight => Key::Shift,
            K::KeyV => Key::V,
            K::KeyG => Key::G,
            K::ArrowUp => Key::Up,
            K::ArrowDown => Key::Down,
            K::ArrowLeft => Key::Left,
            K::ArrowRight => Key::Right,
            K::F1 => Key::F1,
            K::F11 => Key::F11,
            K::F12 => Key::F12,
            K::Escape => Key::Escape,
            _ => return None,
        })
    }
}

/// One input event, from the window or a script.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Input {
    Key {
        key: Key,
        pressed: bool,
    },
    /// Mouse-look motion in pixels (right, down), while a button is held.
    Look {
        dx: f64,
        dy: f64,
    },
    /// Wheel notches (up positive).
    Wheel(f64),
    /// Asks the window for a new inner size in pixels (scripts only).
    Resize {
        width: u32,
        height: u32,
    },
}

/// Events of a script, each with the frame it comes before, in order.
#[derive(Clone, Debug, Default)]
pub struct Script {
    events: Vec<(u64, Input)>,
    next: usize,
}

impl Script {
    /// Reads an EVENTS file; errors name the file and line.
    pub fn load(path: &Path) -> Result<Script> {
        let text = std::fs::read_to_string(path).with_context(|| format!("--input {}", path.display()))?;
        let mut events = Vec::new();
        for (k, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let parsed =
                parse_line(line).with_context(|| format!("--input {} line {}: '{line}'", path.display(), k + 1))?;
            events.extend(parsed);
        }
        events.sort_by_key(|(frame, _)| *frame);
        Ok(Script { events, next: 0 })
    }

    /// The events before frame `frame` not handed out yet.
    pub fn due(&mut self, frame: u64) -> Vec<Input> {
        let start = self.next;
        while self.next < self.events.len() && self.events[self.next].0 <= frame {
            self.next += 1;
        }
        self.events[start..self.next].iter().map(|(_, e)| *e).collect()
    }
}

fn parse_line(line: &str) -> Result<Vec<(u64, Input)>> {
    let words: Vec<&str> = line.split_whitespace().collect();
    let frame: u64 = words[0].parse().context("the first word must be a frame number")?;
    let number = |k: usize| -> Result<f64> {
        let word = words.get(k).context("a number is missing")?;
        let value: f64 = word.parse().with_context(|| format!("'{word}' is not a number"))?;
        if !value.is_finite() || value.abs() > 1e6 {
            bail!("{value} is out of range (|value| ≤ 1e6)");
        }
        Ok(value)
    };
    let inputs = match words.get(1).copied() {
        Some("key") => {
            let name = words.get(2).context("a key name is missing")?;
            let key = Key::parse(name).with_context(|| format!("unknown key '{name}'"))?;
            match words.get(3).copied() {
                Some("down") => vec![Input::Key { key, pressed: true }],
                Some("up") => vec![Input::Key { key, pressed: false }],
                None => vec![Input::Key { key, pressed: true }, Input::Key { key, pressed: false }],
                Some(other) => bail!("'{other}': a key is 'down', 'up' or neither (a press)"),
            }
        }
        Some("mouse") => vec![Input::Look {
            dx: number(2)?,
            dy: number(3)?,
        }],
        Some("wheel") => vec![Input::Wheel(number(2)?)],
        Some("resize") => {
            let side = |k: usize| -> Result<u32> {
                let v = number(k)?;
                if !(1.0..=16384.0).contains(&v) || v.fract() != 0.0 {
                    bail!("{v}: a window side is a whole number of pixels, 1 to 16384");
                }
                Ok(v as u32)
            };
            vec![Input::Resize {
                width: side(2)?,
                height: side(3)?,
            }]
        }
        Some(other) => bail!("unknown event '{other}' (key, mouse, wheel or resize)"),
        None => bail!("an event is missing"),
    };
    Ok(inputs.into_iter().map(|i| (frame, i)).collect())
}

/// The keys held between frames.
#[derive(Clone, Debug, Default)]
pub struct Held {
    keys: Vec<Key>,
}

impl Held {
    pub fn set(&mut self, key: Key, pressed: bool) {
        self.keys.retain(|k| *k != key);
        if pressed {
            self.keys.push(key);
        }
    }

    pub fn is_down(&self, key: Key) -> bool {
        self.keys.contains(&key)
    }

    /// The camera motion the held keys ask for.
    pub fn motion(&self) -> Motion {
        let axis = |plus: &[Key], minus: &[Key]| {
            let down = |keys: &[Key]| keys.iter().any(|k| self.is_down(*k));
            f64::from(u8::from(down(plus))) - f64::from(u8::from(down(minus)))
        };
        Motion {
            forward: axis(&[Key::W], &[Key::S]),
            right: axis(&[Key::D], &[Key::A]),
            up: axis(&[Key::E, Key::Space], &[Key::Q, Key::C]),
            fast: self.is_down(Key::Shift),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_script_is_read_in_frame_order() {
        let dir = std::env::temp_dir().join(format!("alpenglow-script-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("events.txt");
        std::fs::write(
            &path,
            "# comment\n5 key w up\n0 key W down\n3 mouse 4 -2 # look\n3 wheel 1\n7 key F12\n8 resize 64 32\n",
        )
        .unwrap();
        let mut script = Script::load(&path).unwrap();
        let w = |pressed| Input::Key { key: Key::W, pressed };
        assert_eq!(script.due(0), vec![w(true)]);
        assert_eq!(script.due(2), vec![]);
        assert_eq!(
            script.due(4),
            vec![Input::Look { dx: 4.0, dy: -2.0 }, Input::Wheel(1.0)]
        );
        assert_eq!(script.due(6), vec![w(false)]);
        let f12 = |pressed| Input::Key { key: Key::F12, pressed };
        assert_eq!(script.due(7), vec![f12(true), f12(false)]);
        assert_eq!(script.due(100), vec![Input::Resize { width: 64, height: 32 }]);
        for (text, error) in [
            ("x key W", "frame number"),
            ("1 key Z", "unknown key 'Z'"),
            ("1 jump", "unknown event 'jump'"),
            ("1 mouse 1", "a number is missing"),
            ("1 wheel inf", "out of range"),
            ("1 key W sideways", "'sideways'"),
            ("1 resize 0 10", "whole number of pixels"),
            ("1 resize 10.5 10", "whole number of pixels"),
        ] {
            std::fs::write(&path, text).unwrap();
            let message = format!("{:#}", Script::load(&path).unwrap_err());
            assert!(
                message.contains("line 1") && message.contains(error),
                "{text}: {message}"
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn held_keys_make_the_motion() {
        let mut held = Held::default();
        held.set(Key::W, true);
        held.set(Key::A, true);
        held.set(Key::Shift, true);
        held.set(Key::Q, true);
        let m = held.motion();
        assert_eq!((m.forward, m.right, m.up, m.fast), (1.0, -1.0, -1.0, true));
        held.set(Key::W, false);
        held.set(Key::S, true);
        assert_eq!(held.motion().forward, -1.0);
    }
}
