//! Object names: given in the file or made from the table and index, and
//! unique.

use crate::error::Problem;
use toml::Spanned;

/// Object names in the order objects enter the scene's shape list.
#[derive(Default)]
pub(super) struct ObjectNames {
    pub(super) names: Vec<String>,
}

/// The longest object name accepted, in characters.
const MAX_NAME: usize = 60;

impl ObjectNames {
    /// The next object's name: `given`, checked, or `default`.
    pub(super) fn add(
        &mut self,
        given: Option<&Spanned<String>>,
        default: String,
    ) -> Result<(), Problem> {
        let name = self.checked(given, default)?;
        self.names.push(name);
        Ok(())
    }

    /// Face `face` (in `px nx py ny pz nz` order) of the box `field`: the box's
    /// name or field, then the face.
    pub(super) fn add_face(
        &mut self,
        given: Option<&Spanned<String>>,
        field: &str,
        face: usize,
    ) -> Result<(), Problem> {
        const FACES: [&str; 6] = ["px", "nx", "py", "ny", "pz", "nz"];
        let base = self.checked(given, field.to_owned())?;
        self.names.push(format!("{base}.{}", FACES[face]));
        Ok(())
    }

    /// `given` if it is a usable name no other object has, else the problem;
    /// `default` when there is none.
    fn checked(&self, given: Option<&Spanned<String>>, default: String) -> Result<String, Problem> {
        let Some(name) = given else {
            return Ok(default);
        };
        let text = name.get_ref().trim();
        let problem =
            |message: String| Problem::new(name.span(), format!("{default}.name"), message);
        let length = text.chars().count();
        if length == 0 || length > MAX_NAME {
            return Err(problem(format!(
                "expected a name of 1 to {MAX_NAME} characters, got {length}"
            )));
        }
        if text.chars().any(char::is_control) {
            return Err(problem("a name cannot hold control characters".into()));
        }
        if self.names.iter().any(|n| n == text) {
            return Err(problem(format!(
                "another object is already named \"{text}\"; names must differ"
            )));
        }
        Ok(text.to_owned())
    }
}
