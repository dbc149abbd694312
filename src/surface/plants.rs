//! The plant references of the surface material: the procedural plant
//! models a layer's `vegetation` table names (`model = "conifer"`; plant
//! models of dissertation §6.2.1, drawn as sequential point trees, chapter
//! 10 introduction and Fig. 10.12). The models themselves (meshes, point
//! trees, nominal heights) are built by `crate::points::build::plants`.

/// A procedural plant model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum PlantModel {
    /// A spruce-like tree, about 12 m at scale 1 (`points::build::plants::conifer`).
    Conifer,
    /// A broadleaf bush, about 1.8 m at scale 1 (`points::build::plants::shrub`).
    Shrub,
    /// A tuft of grass blades, about 0.5 m at scale 1 (`points::build::plants::grass`).
    GrassTuft,
}

impl PlantModel {
    pub const ALL: [PlantModel; 3] = [PlantModel::Conifer, PlantModel::Shrub, PlantModel::GrassTuft];

    /// The name in layer files (`model = "conifer"`).
    pub fn name(self) -> &'static str {
        match self {
            PlantModel::Conifer => "conifer",
            PlantModel::Shrub => "shrub",
            PlantModel::GrassTuft => "grass_tuft",
        }
    }

    /// The model called `name` ([`PlantModel::name`]).
    pub fn from_name(name: &str) -> Option<PlantModel> {
        PlantModel::ALL.into_iter().find(|m| m.name() == name)
    }
}
