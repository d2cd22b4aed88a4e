//! The two bodies in contact: a first body (a [`Stack`]) pressed against a
//! [`Counterface`], a rigid smooth flat or a second elastic stack (physics.md §6.1).
//!
//! A [`Stack`] is one body and has no counterface of its own, so a counterface's
//! counterface cannot be written down. Every mechanical property the models read —
//! S(ρ) ([`crate::Compliance`]), the contact modulus E*, the length scales,
//! homogeneity — is one of the pair, read through the [`Solid`] trait: a lone
//! [`Stack`] is a body pressed by a rigid flat, [`Bodies`] the pair. Frictionless
//! normal displacements of the two bodies add, so the pair's properties are symmetric
//! in the two bodies to the last bit ([`Solid::canonical_pair`]).

use super::{Base, Conductivity, Stack};

/// No rough surface: the counterface of a table or of a compliance, which knows
/// nothing of surfaces. Uninhabited, so `Option<NoSurface>` is always `None`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoSurface {}

/// How a rigid counterface conducts heat or current (physics.md §6.2).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum RigidConduction {
    /// A conducting half-space of these conductivities (W/(m·K), S/m), each `None`
    /// when not given: C_th,B = 1/(k_B |k|). The default, with neither given.
    HalfSpace(Conductivity),
    /// A perfect conductor (C_th,B = 0; `conduction = "perfect"`).
    #[default]
    Perfect,
}

/// The second body: what the first body is pressed against. `S` is the type of a
/// rough counterface's surface description (the scene's; [`NoSurface`] where there is
/// none, as in a table).
#[derive(Debug, Clone, PartialEq)]
pub enum Counterface<S = NoSurface> {
    /// A rigid flat (the default: smooth, perfectly conducting), conducting as
    /// `conduction` says, smooth or with the rough `surface` (heights as seen from the
    /// first body).
    Rigid {
        conduction: RigidConduction,
        surface: Option<S>,
    },
    /// An elastic stack (itself without a counterface), smooth or with the rough
    /// `surface` (heights as seen from the first body); it conducts through its own
    /// stack's conductivities unless `perfect_conductor` (`conduction = "perfect"`).
    Elastic {
        stack: Stack,
        surface: Option<S>,
        perfect_conductor: bool,
    },
}

impl<S> Default for Counterface<S> {
    fn default() -> Self {
        Counterface::Rigid {
            conduction: RigidConduction::default(),
            surface: None,
        }
    }
}

impl<S> Counterface<S> {
    /// A smooth elastic counterface conducting through its own stack.
    pub fn elastic(stack: Stack) -> Self {
        Counterface::Elastic {
            stack,
            surface: None,
            perfect_conductor: false,
        }
    }

    /// The elastic counterface's stack, `None` for a rigid flat.
    pub fn stack(&self) -> Option<&Stack> {
        match self {
            Counterface::Rigid { .. } => None,
            Counterface::Elastic { stack, .. } => Some(stack),
        }
    }

    /// The rough counterface's surface, if any.
    pub fn surface(&self) -> Option<&S> {
        match self {
            Counterface::Rigid { surface, .. } | Counterface::Elastic { surface, .. } => {
                surface.as_ref()
            }
        }
    }

    /// The counterface with its surface dropped (what a table or a compliance sees).
    pub fn smooth(&self) -> Counterface {
        match self {
            Counterface::Rigid { conduction, .. } => Counterface::Rigid {
                conduction: *conduction,
                surface: None,
            },
            Counterface::Elastic {
                stack,
                perfect_conductor,
                ..
            } => Counterface::Elastic {
                stack: stack.clone(),
                surface: None,
                perfect_conductor: *perfect_conductor,
            },
        }
    }
}

/// The first body and its counterface.
#[derive(Debug, Clone, PartialEq)]
pub struct Bodies<S = NoSurface> {
    /// The first body (its top layer is the contact surface).
    pub first: Stack,
    /// What it is pressed against.
    pub counterface: Counterface<S>,
}

impl<S> Bodies<S> {
    /// `first` pressed by a rigid smooth flat (perfectly conducting).
    pub fn rigid(first: Stack) -> Self {
        Bodies {
            first,
            counterface: Counterface::default(),
        }
    }

    /// `first` pressed against the smooth elastic stack `counterface`.
    pub fn elastic(first: Stack, counterface: Stack) -> Self {
        Bodies {
            first,
            counterface: Counterface::elastic(counterface),
        }
    }

    /// The pair with the counterface's surface dropped.
    pub fn smooth(&self) -> Bodies {
        Bodies {
            first: self.first.clone(),
            counterface: self.counterface.smooth(),
        }
    }
}

/// A solid the models press: a lone [`Stack`] (against a rigid flat) or [`Bodies`].
/// Its mechanical properties are those of the pair (physics.md §6.1).
pub trait Solid {
    /// The first body.
    fn first(&self) -> &Stack;

    /// The elastic counterface's stack, `None` for a rigid flat.
    fn elastic_counterface(&self) -> Option<&Stack>;

    /// The pair as [`Bodies`] (a clone), smooth, a rigid flat with its default
    /// conduction.
    fn bodies<T>(&self) -> Bodies<T> {
        Bodies {
            first: self.first().clone(),
            counterface: match self.elastic_counterface() {
                None => Counterface::default(),
                Some(c) => Counterface::elastic(c.clone()),
            },
        }
    }

    /// The contact modulus E* (Pa) every model normalises by: E*₁ of the top material
    /// against a rigid flat; with an elastic counterface 1/E* = 1/E*₁,A + 1/E*₁,B
    /// (physics.md §6.1, symmetric in A and B to the last bit).
    fn contact_modulus(&self) -> f64 {
        // (IEEE addition is commutative: no canonical order needed for the symmetry)
        let a = self.first().top_plane_strain_modulus();
        match self.elastic_counterface() {
            None => a,
            Some(c) => 1.0 / (1.0 / a + 1.0 / c.top_plane_strain_modulus()),
        }
    }

    /// α = −E*/2 (Pa), the paper's lim 1/F11 (physics.md §2), with E* the
    /// [`contact_modulus`](Self::contact_modulus).
    fn alpha(&self) -> f64 {
        -0.5 * self.contact_modulus()
    }

    /// The reference length h₁ (m): the top layer's thickness; with a counterface the
    /// thinner of the two bodies' top layers (k_z decays like e^{−2ρh₁}). `None` for a
    /// half-space (or two), which has no length scale.
    fn top_thickness(&self) -> Option<f64> {
        let own = self.first().layers().first().map(|l| l.thickness);
        let other = self
            .elastic_counterface()
            .and_then(|c| c.layers().first().map(|l| l.thickness));
        match (own, other) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// Total thickness of the layers (m); with a counterface the larger of the two
    /// bodies' totals (the slowest length scale of S near ρ = 0).
    fn total_thickness(&self) -> f64 {
        let total = |s: &Stack| s.layers().iter().map(|l| l.thickness).sum::<f64>();
        let own = total(self.first());
        match self.elastic_counterface() {
            None => own,
            Some(c) => own.max(total(c)),
        }
    }

    /// True when the solid is mechanically a homogeneous half-space (k_z ≡ 0): an
    /// elastic base and every layer of the same material as the base — for both
    /// bodies when there is a counterface (their E* is then the contact modulus).
    fn is_homogeneous(&self) -> bool {
        let one = |s: &Stack| match s.base() {
            Base::Rigid => false,
            Base::Elastic { young, poisson } => s
                .layers()
                .iter()
                .all(|l| l.young == young && l.poisson == poisson),
        };
        one(self.first()) && self.elastic_counterface().is_none_or(one)
    }

    /// True when S(0) = 0: a rigid base under the first body and, with a counterface,
    /// under the counterface too (then a uniform pressure gives a finite deflection).
    fn on_rigid_bases(&self) -> bool {
        let rigid = |s: &Stack| matches!(s.base(), Base::Rigid);
        rigid(self.first()) && self.elastic_counterface().is_none_or(rigid)
    }

    /// The two elastic bodies in a canonical order (the one whose Debug form, without
    /// its name, sorts first comes first), so that a pair and its swap compute S(ρ)
    /// and E* with the same floating-point operations (physics.md §6.1: swapping
    /// changes nothing). `None` against a rigid flat.
    fn canonical_pair(&self) -> Option<(Stack, Stack)> {
        let mut b = self.elastic_counterface()?.clone();
        let mut a = self.first().clone();
        a.name = None;
        b.name = None;
        if format!("{a:?}") <= format!("{b:?}") {
            Some((a, b))
        } else {
            Some((b, a))
        }
    }
}

impl Solid for Stack {
    fn first(&self) -> &Stack {
        self
    }

    fn elastic_counterface(&self) -> Option<&Stack> {
        None
    }
}

impl<S> Solid for Bodies<S> {
    fn first(&self) -> &Stack {
        &self.first
    }

    fn elastic_counterface(&self) -> Option<&Stack> {
        self.counterface.stack()
    }
}

impl<T: Solid + ?Sized> Solid for &T {
    fn first(&self) -> &Stack {
        (**self).first()
    }

    fn elastic_counterface(&self) -> Option<&Stack> {
        (**self).elastic_counterface()
    }
}

impl From<Stack> for Bodies {
    fn from(first: Stack) -> Bodies {
        Bodies::rigid(first)
    }
}
