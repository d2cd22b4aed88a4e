!> strata: Fortran 2008 bindings of the strata C ABI (capi/include/strata.h).
!>
!> The contact law of a rough layered interface from Fortran: load a surrogate table,
!> generate or load a surface or pass its heights (strata_surface_new), give the stack
!> as a file or as arrays (strata_stack_new), solve the load curve once
!> (strata_law_new, strata_law_new_from_stack), then query the mean contact pressure
!> p(g) (Pa), the real contact-area fraction A(g)/A0 and the tangent dp/dg (Pa/m) at
!> any mean-plane separation g (m), alone or all three at once, at one gap or an array
!> of them (strata_law_eval, strata_law_eval_array). SI units throughout. The law's
!> effects (strata_law_new_with_law_options with a strata_law_options): a hardness
!> (capped asperity tips) and the interface conductance h_c (strata_law_conductance*;
!> per-layer conductivities from memory with strata_stack_set_conductivities).
!>
!> Two layers:
!>  * c_strata_* : the C functions as declared in strata.h (bind(C)), pointer arguments
!>    as type(c_ptr) by value, so that NULL can be passed as in C;
!>  * strata_*   : wrappers taking Fortran strings (trailing blanks trimmed, the NUL
!>    added here), default integers for counts, returning messages and the version as
!>    deferred-length strings, and setting handles to c_null_ptr when freed or when a
!>    constructor fails.
!> Every function returns STRATA_OK (0) or a STRATA_ERR_* code; on error
!> strata_last_error_message() is the one-line message naming the offending argument.
!> Handles (table, stack, surface, law) are type(c_ptr); free them with strata_*_free.
!>
!> Build (from the repository root, after `cargo build -p strata-capi`):
!>   gfortran -std=f2008 capi/fortran/strata.f90 examples/fortran/law_example.f90 \
!>     -L target/debug -lstrata_capi -Wl,-rpath,$PWD/target/debug -o law_example_f
!> The constants below equal the header's #defines (checked by capi/tests/c_example.rs).
module strata
  use, intrinsic :: iso_c_binding, only: c_associated, c_char, c_double, c_f_pointer, &
       c_int32_t, c_int64_t, c_loc, c_null_char, c_null_ptr, c_ptr, c_size_t
  implicit none
  private

  public :: c_ptr, c_null_ptr, c_double, c_int32_t, c_int64_t, c_size_t

  !> Success.
  integer(c_int32_t), parameter, public :: STRATA_OK = 0
  !> A required pointer argument was NULL.
  integer(c_int32_t), parameter, public :: STRATA_ERR_NULL = 1
  !> An argument is out of its domain (non-finite number, unknown model or format,
  !> too few or too many samples, a layered stack without a table, a bad min_gap...).
  integer(c_int32_t), parameter, public :: STRATA_ERR_INVALID_ARGUMENT = 2
  !> The table file is missing, unreadable, corrupt, or does not serve the stack.
  integer(c_int32_t), parameter, public :: STRATA_ERR_TABLE = 3
  !> The stack file is missing, unreadable or invalid, or a strata_stack_new value is.
  integer(c_int32_t), parameter, public :: STRATA_ERR_STACK = 4
  !> The surface file or its generation parameters are invalid.
  integer(c_int32_t), parameter, public :: STRATA_ERR_SURFACE = 5
  !> The rough-contact solve failed.
  integer(c_int32_t), parameter, public :: STRATA_ERR_SOLVE = 6
  !> A query below the smallest sampled separation of the law.
  integer(c_int32_t), parameter, public :: STRATA_ERR_OUT_OF_RANGE = 7
  !> Writing an output file failed.
  integer(c_int32_t), parameter, public :: STRATA_ERR_IO = 8
  !> The estimated memory of a request exceeds the limit (STRATA_MEMORY_LIMIT).
  integer(c_int32_t), parameter, public :: STRATA_ERR_RESOURCE = 9
  !> An internal error (a Rust panic caught at the boundary): please report it.
  integer(c_int32_t), parameter, public :: STRATA_ERR_PANIC = 99
  !> Largest number of samples of strata_law_new.
  integer(c_size_t), parameter, public :: STRATA_MAX_SAMPLES = 100000_c_size_t
  !> N model: independent asperities.
  integer(c_int32_t), parameter, public :: STRATA_MODEL_INDEPENDENT = 0
  !> I model: interacting asperities, interactions inside the sample only.
  integer(c_int32_t), parameter, public :: STRATA_MODEL_INTERACTING_ISOLATED = 1
  !> I model: interacting asperities, the sample repeated periodically (5x5 cells).
  integer(c_int32_t), parameter, public :: STRATA_MODEL_INTERACTING_PERIODIC = 2
  !> Version of the library the header belongs to (strata_version(): the one linked).
  integer(c_int32_t), parameter, public :: STRATA_VERSION_MAJOR = 0
  integer(c_int32_t), parameter, public :: STRATA_VERSION_MINOR = 1
  integer(c_int32_t), parameter, public :: STRATA_VERSION_PATCH = 0
  !> strata_stack_new: the last layer is bonded to a rigid base.
  integer(c_int32_t), parameter, public :: STRATA_BASE_RIGID = 0
  !> strata_stack_new: the layers lie on an elastic half-space.
  integer(c_int32_t), parameter, public :: STRATA_BASE_ELASTIC = 1
  !> strata_law_write: CSV gap,overclosure,mean_pressure,area_fraction,dp_dg.
  integer(c_int32_t), parameter, public :: STRATA_FORMAT_CSV = 0
  !> strata_law_write: Abaqus/CalculiX *SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TABULAR.
  integer(c_int32_t), parameter, public :: STRATA_FORMAT_ABAQUS = 1
  !> strata_law_options%conductance_kind: none, thermal h_c (W/(m^2 K)), electrical (S/m^2).
  integer(c_int32_t), parameter, public :: STRATA_CONDUCTANCE_NONE = 0
  integer(c_int32_t), parameter, public :: STRATA_CONDUCTANCE_THERMAL = 1
  integer(c_int32_t), parameter, public :: STRATA_CONDUCTANCE_ELECTRICAL = 2
  !> strata_law_options%counterface_conduction: the elastic counterface's own stack, a
  !> perfect conductor, a conducting half-space of counterface_conductivity.
  integer(c_int32_t), parameter, public :: STRATA_COUNTERFACE_CONDUCTION_STACK = 0
  integer(c_int32_t), parameter, public :: STRATA_COUNTERFACE_CONDUCTION_PERFECT = 1
  integer(c_int32_t), parameter, public :: STRATA_COUNTERFACE_CONDUCTION_HALF_SPACE = 2
  !> strata_stack_set_conductivities: a conducting half-space base, an isothermal sink.
  integer(c_int32_t), parameter, public :: STRATA_BASE_CONDUCTION_HALF_SPACE = 0
  integer(c_int32_t), parameter, public :: STRATA_BASE_CONDUCTION_ISOTHERMAL = 1

  public :: c_strata_last_error_message, c_strata_version, c_strata_table_load, &
       c_strata_table_free, c_strata_surface_load, c_strata_surface_read, &
       c_strata_surface_info, c_strata_surface_generate, c_strata_surface_free, c_strata_law_new, c_strata_law_pressure, &
       c_strata_solver_options_default, c_strata_law_new_with_options, &
       c_strata_law_area_fraction, c_strata_law_dp_dg, c_strata_law_first_contact_gap, &
       c_strata_law_min_gap, c_strata_law_write, c_strata_law_free, &
       c_strata_stack_new, c_strata_stack_free, c_strata_surface_new, &
       c_strata_law_new_from_stack, c_strata_law_eval, c_strata_law_eval_array, &
       c_strata_stack_load, c_strata_stack_set_conductivities, c_strata_law_options_default, &
       c_strata_law_new_with_law_options, c_strata_law_conductance_kind, &
       c_strata_law_hardness, c_strata_law_tangential_stiffness, &
       c_strata_law_conductance, c_strata_law_conductance_array, &
       c_strata_law_conductance_at_pressure, c_strata_law_conductance_at_pressure_array, &
       c_strata_law_eval_with_conductance
  public :: strata_last_error_message, strata_version, strata_table_load, &
       strata_table_free, strata_surface_load, strata_surface_read, strata_surface_info, &
       strata_surface_generate, strata_surface_free, strata_law_new, strata_law_pressure, &
       strata_solver_options_default, strata_law_new_with_options, &
       strata_law_area_fraction, strata_law_dp_dg, strata_law_first_contact_gap, &
       strata_law_min_gap, strata_law_write, strata_law_free, &
       strata_stack_new, strata_stack_free, strata_surface_new, &
       strata_law_new_from_stack, strata_law_eval, strata_law_eval_array, &
       strata_stack_load, strata_stack_set_conductivities, strata_law_options_default, &
       strata_law_new_with_law_options, strata_law_conductance_kind, strata_law_hardness, &
       strata_law_tangential_stiffness, &
       strata_law_conductance, strata_law_conductance_array, &
       strata_law_conductance_at_pressure, strata_law_conductance_at_pressure_array, &
       strata_law_eval_with_conductance

  !> StrataSolverOptions: budgets and tolerances of strata_law_new_with_options (the
  !> scene's [solver] keys of the asperity models; fill with strata_solver_options_default).
  type, bind(C), public :: strata_solver_options
     integer(c_size_t) :: max_step_newton_steps
     integer(c_size_t) :: max_step_evaluations
     real(c_double) :: kkt_tolerance
     integer(c_size_t) :: max_pressure_iterations
  end type strata_solver_options

  !> StrataLawOptions: the law's effects for strata_law_new_with_law_options (fill with
  !> strata_law_options_default, which sets `size`): the hardness of the asperity tips
  !> (Pa; 0 or +Inf: elastic), the interface conductance to solve
  !> (STRATA_CONDUCTANCE_*), how the counterface conducts, and the coefficient of
  !> friction (0: none; > 0: the law carries the full-stick tangential stiffness).
  type, bind(C), public :: strata_law_options
     integer(c_size_t) :: size
     real(c_double) :: hardness
     integer(c_int32_t) :: conductance_kind
     integer(c_int32_t) :: counterface_conduction
     real(c_double) :: counterface_conductivity
     real(c_double) :: friction_coefficient
  end type strata_law_options

  interface
     !> const char *strata_last_error_message(void)
     function c_strata_last_error_message() bind(C, name="strata_last_error_message") &
          result(message)
       import :: c_ptr
       type(c_ptr) :: message
     end function c_strata_last_error_message

     !> const char *strata_version(void)
     function c_strata_version() bind(C, name="strata_version") result(version)
       import :: c_ptr
       type(c_ptr) :: version
     end function c_strata_version

     !> int32_t strata_table_load(const char *path, StrataTable **out)
     function c_strata_table_load(path, out) bind(C, name="strata_table_load") result(code)
       import :: c_char, c_int32_t, c_ptr
       character(kind=c_char), dimension(*), intent(in) :: path
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_table_load

     !> void strata_table_free(StrataTable *table)
     subroutine c_strata_table_free(table) bind(C, name="strata_table_free")
       import :: c_ptr
       type(c_ptr), value :: table
     end subroutine c_strata_table_free

     !> int32_t strata_surface_load(const char *path, double size, int32_t periodic,
     !>                             StrataSurface **out)
     function c_strata_surface_load(path, size, periodic, out) &
          bind(C, name="strata_surface_load") result(code)
       import :: c_char, c_double, c_int32_t, c_ptr
       character(kind=c_char), dimension(*), intent(in) :: path
       real(c_double), value :: size
       integer(c_int32_t), value :: periodic
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_surface_load

     !> int32_t strata_surface_read(const char *path, double dx, double dy,
     !>     const char *height_unit, const char *detrend, int32_t periodic,
     !>     StrataSurface **out)
     function c_strata_surface_read(path, dx, dy, height_unit, detrend, periodic, out) &
          bind(C, name="strata_surface_read") result(code)
       import :: c_char, c_double, c_int32_t, c_ptr
       character(kind=c_char), dimension(*), intent(in) :: path, height_unit, detrend
       real(c_double), value :: dx, dy
       integer(c_int32_t), value :: periodic
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_surface_read

     !> int32_t strata_surface_info(const StrataSurface *surface, size_t *nx,
     !>     size_t *ny, double *dx, double *dy, double *rms)
     function c_strata_surface_info(surface, nx, ny, dx, dy, rms) &
          bind(C, name="strata_surface_info") result(code)
       import :: c_double, c_int32_t, c_ptr, c_size_t
       type(c_ptr), value :: surface
       integer(c_size_t), intent(out) :: nx, ny
       real(c_double), intent(out) :: dx, dy, rms
       integer(c_int32_t) :: code
     end function c_strata_surface_info

     !> int32_t strata_surface_generate(double size, size_t grid, double fractal_dimension,
     !>     double k_min, double k_max, double rms, uint64_t seed, StrataSurface **out)
     function c_strata_surface_generate(size, grid, fractal_dimension, k_min, k_max, rms, &
          seed, out) bind(C, name="strata_surface_generate") result(code)
       import :: c_double, c_int32_t, c_int64_t, c_ptr, c_size_t
       real(c_double), value :: size
       integer(c_size_t), value :: grid
       real(c_double), value :: fractal_dimension, k_min, k_max, rms
       integer(c_int64_t), value :: seed
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_surface_generate

     !> void strata_surface_free(StrataSurface *surface)
     subroutine c_strata_surface_free(surface) bind(C, name="strata_surface_free")
       import :: c_ptr
       type(c_ptr), value :: surface
     end subroutine c_strata_surface_free

     !> int32_t strata_law_new(const StrataTable *table, const char *stack_path,
     !>     const StrataSurface *surface, int32_t model, double min_gap, size_t samples,
     !>     StrataLaw **out)
     function c_strata_law_new(table, stack_path, surface, model, min_gap, samples, out) &
          bind(C, name="strata_law_new") result(code)
       import :: c_char, c_double, c_int32_t, c_ptr, c_size_t
       type(c_ptr), value :: table
       character(kind=c_char), dimension(*), intent(in) :: stack_path
       type(c_ptr), value :: surface
       integer(c_int32_t), value :: model
       real(c_double), value :: min_gap
       integer(c_size_t), value :: samples
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_law_new

     !> int32_t strata_solver_options_default(StrataSolverOptions *out)
     function c_strata_solver_options_default(out) &
          bind(C, name="strata_solver_options_default") result(code)
       import :: c_int32_t, c_ptr
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_solver_options_default

     !> int32_t strata_law_new_with_options(const StrataTable *table,
     !>     const char *stack_path, const StrataSurface *surface, int32_t model,
     !>     double min_gap, size_t samples, const StrataSolverOptions *options,
     !>     StrataLaw **out)
     function c_strata_law_new_with_options(table, stack_path, surface, model, min_gap, &
          samples, options, out) bind(C, name="strata_law_new_with_options") result(code)
       import :: c_char, c_double, c_int32_t, c_ptr, c_size_t
       type(c_ptr), value :: table
       character(kind=c_char), dimension(*), intent(in) :: stack_path
       type(c_ptr), value :: surface
       integer(c_int32_t), value :: model
       real(c_double), value :: min_gap
       integer(c_size_t), value :: samples
       type(c_ptr), value :: options
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_law_new_with_options

     !> int32_t strata_law_pressure(const StrataLaw *law, double gap, double *out)
     function c_strata_law_pressure(law, gap, out) bind(C, name="strata_law_pressure") &
          result(code)
       import :: c_double, c_int32_t, c_ptr
       type(c_ptr), value :: law
       real(c_double), value :: gap
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_law_pressure

     !> int32_t strata_law_area_fraction(const StrataLaw *law, double gap, double *out)
     function c_strata_law_area_fraction(law, gap, out) &
          bind(C, name="strata_law_area_fraction") result(code)
       import :: c_double, c_int32_t, c_ptr
       type(c_ptr), value :: law
       real(c_double), value :: gap
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_law_area_fraction

     !> int32_t strata_law_dp_dg(const StrataLaw *law, double gap, double *out)
     function c_strata_law_dp_dg(law, gap, out) bind(C, name="strata_law_dp_dg") &
          result(code)
       import :: c_double, c_int32_t, c_ptr
       type(c_ptr), value :: law
       real(c_double), value :: gap
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_law_dp_dg

     !> int32_t strata_law_first_contact_gap(const StrataLaw *law, double *out)
     function c_strata_law_first_contact_gap(law, out) &
          bind(C, name="strata_law_first_contact_gap") result(code)
       import :: c_int32_t, c_ptr
       type(c_ptr), value :: law
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_law_first_contact_gap

     !> int32_t strata_law_min_gap(const StrataLaw *law, double *out)
     function c_strata_law_min_gap(law, out) bind(C, name="strata_law_min_gap") result(code)
       import :: c_int32_t, c_ptr
       type(c_ptr), value :: law
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_law_min_gap

     !> int32_t strata_law_write(const StrataLaw *law, const char *path, int32_t format)
     function c_strata_law_write(law, path, format) bind(C, name="strata_law_write") &
          result(code)
       import :: c_char, c_int32_t, c_ptr
       type(c_ptr), value :: law
       character(kind=c_char), dimension(*), intent(in) :: path
       integer(c_int32_t), value :: format
       integer(c_int32_t) :: code
     end function c_strata_law_write

     !> void strata_law_free(StrataLaw *law)
     subroutine c_strata_law_free(law) bind(C, name="strata_law_free")
       import :: c_ptr
       type(c_ptr), value :: law
     end subroutine c_strata_law_free

     !> int32_t strata_stack_new(size_t n_layers, const double *thickness,
     !>     const double *young, const double *poisson, int32_t base_kind,
     !>     double base_young, double base_poisson, StrataStack **out)
     function c_strata_stack_new(n_layers, thickness, young, poisson, base_kind, &
          base_young, base_poisson, out) bind(C, name="strata_stack_new") result(code)
       import :: c_double, c_int32_t, c_ptr, c_size_t
       integer(c_size_t), value :: n_layers
       type(c_ptr), value :: thickness, young, poisson
       integer(c_int32_t), value :: base_kind
       real(c_double), value :: base_young, base_poisson
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_stack_new

     !> void strata_stack_free(StrataStack *stack)
     subroutine c_strata_stack_free(stack) bind(C, name="strata_stack_free")
       import :: c_ptr
       type(c_ptr), value :: stack
     end subroutine c_strata_stack_free

     !> int32_t strata_surface_new(const double *heights, size_t nx, size_t ny,
     !>     double dx, double dy, int32_t periodic, StrataSurface **out)
     function c_strata_surface_new(heights, nx, ny, dx, dy, periodic, out) &
          bind(C, name="strata_surface_new") result(code)
       import :: c_double, c_int32_t, c_ptr, c_size_t
       type(c_ptr), value :: heights
       integer(c_size_t), value :: nx, ny
       real(c_double), value :: dx, dy
       integer(c_int32_t), value :: periodic
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_surface_new

     !> int32_t strata_law_new_from_stack(const StrataTable *table,
     !>     const StrataStack *stack, const StrataSurface *surface, int32_t model,
     !>     double min_gap, size_t samples, const StrataSolverOptions *options,
     !>     StrataLaw **out)
     function c_strata_law_new_from_stack(table, stack, surface, model, min_gap, samples, &
          options, out) bind(C, name="strata_law_new_from_stack") result(code)
       import :: c_double, c_int32_t, c_ptr, c_size_t
       type(c_ptr), value :: table, stack, surface
       integer(c_int32_t), value :: model
       real(c_double), value :: min_gap
       integer(c_size_t), value :: samples
       type(c_ptr), value :: options
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_law_new_from_stack

     !> int32_t strata_law_eval(const StrataLaw *law, double gap, double *pressure,
     !>     double *area_fraction, double *dp_dg)
     function c_strata_law_eval(law, gap, pressure, area_fraction, dp_dg) &
          bind(C, name="strata_law_eval") result(code)
       import :: c_double, c_int32_t, c_ptr
       type(c_ptr), value :: law
       real(c_double), value :: gap
       type(c_ptr), value :: pressure, area_fraction, dp_dg
       integer(c_int32_t) :: code
     end function c_strata_law_eval

     !> int32_t strata_law_eval_array(const StrataLaw *law, size_t n, const double *gaps,
     !>     double *pressure, double *area_fraction, double *dp_dg)
     function c_strata_law_eval_array(law, n, gaps, pressure, area_fraction, dp_dg) &
          bind(C, name="strata_law_eval_array") result(code)
       import :: c_int32_t, c_ptr, c_size_t
       type(c_ptr), value :: law
       integer(c_size_t), value :: n
       type(c_ptr), value :: gaps, pressure, area_fraction, dp_dg
       integer(c_int32_t) :: code
     end function c_strata_law_eval_array

     !> int32_t strata_stack_load(const char *path, StrataStack **out)
     function c_strata_stack_load(path, out) bind(C, name="strata_stack_load") result(code)
       import :: c_char, c_int32_t, c_ptr
       character(kind=c_char), dimension(*), intent(in) :: path
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_stack_load

     !> int32_t strata_stack_set_conductivities(StrataStack *stack, int32_t kind,
     !>     size_t n_layers, const double *conductivity, int32_t base_conduction,
     !>     double base_conductivity)
     function c_strata_stack_set_conductivities(stack, kind, n_layers, conductivity, &
          base_conduction, base_conductivity) &
          bind(C, name="strata_stack_set_conductivities") result(code)
       import :: c_double, c_int32_t, c_ptr, c_size_t
       type(c_ptr), value :: stack
       integer(c_int32_t), value :: kind
       integer(c_size_t), value :: n_layers
       type(c_ptr), value :: conductivity
       integer(c_int32_t), value :: base_conduction
       real(c_double), value :: base_conductivity
       integer(c_int32_t) :: code
     end function c_strata_stack_set_conductivities

     !> int32_t strata_law_options_default(StrataLawOptions *out)
     function c_strata_law_options_default(out) &
          bind(C, name="strata_law_options_default") result(code)
       import :: c_int32_t, c_ptr
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_law_options_default

     !> int32_t strata_law_new_with_law_options(const StrataTable *table,
     !>     const StrataStack *stack, const StrataSurface *surface, int32_t model,
     !>     double min_gap, size_t samples, const StrataSolverOptions *solver_options,
     !>     const StrataLawOptions *law_options, StrataLaw **out)
     function c_strata_law_new_with_law_options(table, stack, surface, model, min_gap, &
          samples, solver_options, law_options, out) &
          bind(C, name="strata_law_new_with_law_options") result(code)
       import :: c_double, c_int32_t, c_ptr, c_size_t
       type(c_ptr), value :: table, stack, surface
       integer(c_int32_t), value :: model
       real(c_double), value :: min_gap
       integer(c_size_t), value :: samples
       type(c_ptr), value :: solver_options, law_options, out
       integer(c_int32_t) :: code
     end function c_strata_law_new_with_law_options

     !> int32_t strata_law_conductance_kind(const StrataLaw *law, int32_t *out)
     function c_strata_law_conductance_kind(law, out) &
          bind(C, name="strata_law_conductance_kind") result(code)
       import :: c_int32_t, c_ptr
       type(c_ptr), value :: law, out
       integer(c_int32_t) :: code
     end function c_strata_law_conductance_kind

     !> int32_t strata_law_hardness(const StrataLaw *law, double *out)
     function c_strata_law_hardness(law, out) bind(C, name="strata_law_hardness") &
          result(code)
       import :: c_int32_t, c_ptr
       type(c_ptr), value :: law, out
       integer(c_int32_t) :: code
     end function c_strata_law_hardness

     !> int32_t strata_law_tangential_stiffness(const StrataLaw *law, double gap, double *out)
     function c_strata_law_tangential_stiffness(law, gap, out) &
          bind(C, name="strata_law_tangential_stiffness") result(code)
       import :: c_double, c_int32_t, c_ptr
       type(c_ptr), value :: law
       real(c_double), value :: gap
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_law_tangential_stiffness

     !> int32_t strata_law_conductance(const StrataLaw *law, double gap, double *out)
     function c_strata_law_conductance(law, gap, out) &
          bind(C, name="strata_law_conductance") result(code)
       import :: c_double, c_int32_t, c_ptr
       type(c_ptr), value :: law
       real(c_double), value :: gap
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_law_conductance

     !> int32_t strata_law_conductance_array(const StrataLaw *law, size_t n,
     !>     const double *gaps, double *out)
     function c_strata_law_conductance_array(law, n, gaps, out) &
          bind(C, name="strata_law_conductance_array") result(code)
       import :: c_int32_t, c_ptr, c_size_t
       type(c_ptr), value :: law
       integer(c_size_t), value :: n
       type(c_ptr), value :: gaps, out
       integer(c_int32_t) :: code
     end function c_strata_law_conductance_array

     !> int32_t strata_law_conductance_at_pressure(const StrataLaw *law, double pressure,
     !>     double *out)
     function c_strata_law_conductance_at_pressure(law, pressure, out) &
          bind(C, name="strata_law_conductance_at_pressure") result(code)
       import :: c_double, c_int32_t, c_ptr
       type(c_ptr), value :: law
       real(c_double), value :: pressure
       type(c_ptr), value :: out
       integer(c_int32_t) :: code
     end function c_strata_law_conductance_at_pressure

     !> int32_t strata_law_conductance_at_pressure_array(const StrataLaw *law, size_t n,
     !>     const double *pressures, double *out)
     function c_strata_law_conductance_at_pressure_array(law, n, pressures, out) &
          bind(C, name="strata_law_conductance_at_pressure_array") result(code)
       import :: c_int32_t, c_ptr, c_size_t
       type(c_ptr), value :: law
       integer(c_size_t), value :: n
       type(c_ptr), value :: pressures, out
       integer(c_int32_t) :: code
     end function c_strata_law_conductance_at_pressure_array

     !> int32_t strata_law_eval_with_conductance(const StrataLaw *law, double gap,
     !>     double *pressure, double *area_fraction, double *dp_dg, double *conductance)
     function c_strata_law_eval_with_conductance(law, gap, pressure, area_fraction, dp_dg, &
          conductance) bind(C, name="strata_law_eval_with_conductance") result(code)
       import :: c_double, c_int32_t, c_ptr
       type(c_ptr), value :: law
       real(c_double), value :: gap
       type(c_ptr), value :: pressure, area_fraction, dp_dg, conductance
       integer(c_int32_t) :: code
     end function c_strata_law_eval_with_conductance

     !> size_t strlen(const char *s), for the C strings the library returns.
     function c_strlen(s) bind(C, name="strlen") result(n)
       import :: c_ptr, c_size_t
       type(c_ptr), value :: s
       integer(c_size_t) :: n
     end function c_strlen
  end interface

contains

  !> A NUL-terminated copy of a Fortran string (trailing blanks removed).
  pure function c_path(path) result(s)
    character(*), intent(in) :: path
    character(kind=c_char, len=len_trim(path) + 1) :: s
    s = trim(path) // c_null_char
  end function c_path

  !> A Fortran copy of a NUL-terminated C string ("" for NULL).
  function f_string(p) result(s)
    type(c_ptr), intent(in) :: p
    character(:), allocatable :: s
    character(kind=c_char), pointer :: chars(:)
    integer(c_size_t) :: n, i
    if (.not. c_associated(p)) then
       s = ""
       return
    end if
    n = c_strlen(p)
    call c_f_pointer(p, chars, [n])
    allocate (character(len=n) :: s)
    do i = 1, n
       s(i:i) = chars(i)
    end do
  end function f_string

  !> The message of the most recent failing call on this thread ("" if none).
  function strata_last_error_message() result(message)
    character(:), allocatable :: message
    message = f_string(c_strata_last_error_message())
  end function strata_last_error_message

  !> The library version, e.g. "0.1.0".
  function strata_version() result(version)
    character(:), allocatable :: version
    version = f_string(c_strata_version())
  end function strata_version

  !> Loads a surrogate table file (`strata table build`) into `table`.
  function strata_table_load(path, table) result(code)
    character(*), intent(in) :: path
    type(c_ptr), intent(out), target :: table
    integer(c_int32_t) :: code
    table = c_null_ptr
    code = c_strata_table_load(c_path(path), c_loc(table))
  end function strata_table_load

  !> Frees a table (c_null_ptr is a no-op) and sets the handle to c_null_ptr.
  subroutine strata_table_free(table)
    type(c_ptr), intent(inout) :: table
    call c_strata_table_free(table)
    table = c_null_ptr
  end subroutine strata_table_free

  !> Loads a surface height map (m): a 2-D f64 .npy file by extension, otherwise a text
  !> matrix; `size` is the length L (m) of the first axis.
  function strata_surface_load(path, size, periodic, surface) result(code)
    character(*), intent(in) :: path
    real(c_double), intent(in) :: size
    logical, intent(in) :: periodic
    type(c_ptr), intent(out), target :: surface
    integer(c_int32_t) :: code
    integer(c_int32_t) :: flag
    flag = 0
    if (periodic) flag = 1
    surface = c_null_ptr
    code = c_strata_surface_load(c_path(path), size, flag, c_loc(surface))
  end function strata_surface_load

  !> Reads a measured surface: .x3p (pixel sizes and metres from the file: dx = dy = 0),
  !> a 2-D f64 .npy or a text matrix with pixel sizes dx, dy (m); `height_unit` "m",
  !> "mm", "um", "nm" ("" = metres), `detrend` "none", "plane", "curvature" ("" = none).
  function strata_surface_read(path, dx, dy, height_unit, detrend, periodic, surface) &
       result(code)
    character(*), intent(in) :: path, height_unit, detrend
    real(c_double), intent(in) :: dx, dy
    logical, intent(in) :: periodic
    type(c_ptr), intent(out), target :: surface
    integer(c_int32_t) :: code
    integer(c_int32_t) :: flag
    flag = 0
    if (periodic) flag = 1
    surface = c_null_ptr
    code = c_strata_surface_read(c_path(path), dx, dy, c_path(height_unit), &
         c_path(detrend), flag, c_loc(surface))
  end function strata_surface_read

  !> The grid (nx x ny points, first axis = x), pixel sizes dx, dy (m) and RMS height
  !> (m) of a surface.
  function strata_surface_info(surface, nx, ny, dx, dy, rms) result(code)
    type(c_ptr), intent(in) :: surface
    integer, intent(out) :: nx, ny
    real(c_double), intent(out) :: dx, dy, rms
    integer(c_int32_t) :: code
    integer(c_size_t) :: n0, n1
    code = c_strata_surface_info(surface, n0, n1, dx, dy, rms)
    nx = int(n0)
    ny = int(n1)
  end function strata_surface_info

  !> Generates a periodic self-affine surface: side `size` (m), `grid` points per side,
  !> fractal dimension in [2, 3), wavenumbers k_min..k_max (units of 2 pi/L), RMS
  !> height `rms` (m), seed.
  function strata_surface_generate(size, grid, fractal_dimension, k_min, k_max, rms, seed, &
       surface) result(code)
    real(c_double), intent(in) :: size, fractal_dimension, k_min, k_max, rms
    integer, intent(in) :: grid
    integer(c_int64_t), intent(in) :: seed
    type(c_ptr), intent(out), target :: surface
    integer(c_int32_t) :: code
    surface = c_null_ptr
    code = c_strata_surface_generate(size, int(grid, c_size_t), fractal_dimension, k_min, &
         k_max, rms, seed, c_loc(surface))
  end function strata_surface_generate

  !> Frees a surface (c_null_ptr is a no-op) and sets the handle to c_null_ptr.
  subroutine strata_surface_free(surface)
    type(c_ptr), intent(inout) :: surface
    call c_strata_surface_free(surface)
    surface = c_null_ptr
  end subroutine strata_surface_free

  !> Builds the contact law of `surface` on the stack file `stack_path`, `model` one of
  !> STRATA_MODEL_*, `samples` (2 to STRATA_MAX_SAMPLES) separations from first contact
  !> down to `min_gap` (m). `table` may be c_null_ptr for a homogeneous stack. A
  !> negative `samples` reaches C as a huge size_t and is refused.
  function strata_law_new(table, stack_path, surface, model, min_gap, samples, law) &
       result(code)
    type(c_ptr), intent(in) :: table, surface
    character(*), intent(in) :: stack_path
    integer(c_int32_t), intent(in) :: model
    real(c_double), intent(in) :: min_gap
    integer, intent(in) :: samples
    type(c_ptr), intent(out), target :: law
    integer(c_int32_t) :: code
    law = c_null_ptr
    code = c_strata_law_new(table, c_path(stack_path), surface, model, min_gap, &
         int(samples, c_size_t), c_loc(law))
  end function strata_law_new

  !> The default solver options (those strata_law_new uses).
  function strata_solver_options_default(options) result(code)
    type(strata_solver_options), intent(out), target :: options
    integer(c_int32_t) :: code
    code = c_strata_solver_options_default(c_loc(options))
  end function strata_solver_options_default

  !> strata_law_new with the solver's budgets and tolerances from `options`.
  function strata_law_new_with_options(table, stack_path, surface, model, min_gap, &
       samples, options, law) result(code)
    type(c_ptr), intent(in) :: table, surface
    character(*), intent(in) :: stack_path
    integer(c_int32_t), intent(in) :: model
    real(c_double), intent(in) :: min_gap
    integer, intent(in) :: samples
    type(strata_solver_options), intent(in), target :: options
    type(c_ptr), intent(out), target :: law
    integer(c_int32_t) :: code
    law = c_null_ptr
    code = c_strata_law_new_with_options(table, c_path(stack_path), surface, model, &
         min_gap, int(samples, c_size_t), c_loc(options), c_loc(law))
  end function strata_law_new_with_options

  !> Mean contact pressure p(g) (Pa) at separation `gap` (m); `p` unchanged on error.
  function strata_law_pressure(law, gap, p) result(code)
    type(c_ptr), intent(in) :: law
    real(c_double), intent(in) :: gap
    real(c_double), intent(inout), target :: p
    integer(c_int32_t) :: code
    code = c_strata_law_pressure(law, gap, c_loc(p))
  end function strata_law_pressure

  !> Real contact-area fraction A(g)/A0 at separation `gap` (m); `a` unchanged on error.
  function strata_law_area_fraction(law, gap, a) result(code)
    type(c_ptr), intent(in) :: law
    real(c_double), intent(in) :: gap
    real(c_double), intent(inout), target :: a
    integer(c_int32_t) :: code
    code = c_strata_law_area_fraction(law, gap, c_loc(a))
  end function strata_law_area_fraction

  !> Tangent dp/dg (Pa/m, <= 0) at separation `gap` (m); `d` unchanged on error.
  function strata_law_dp_dg(law, gap, d) result(code)
    type(c_ptr), intent(in) :: law
    real(c_double), intent(in) :: gap
    real(c_double), intent(inout), target :: d
    integer(c_int32_t) :: code
    code = c_strata_law_dp_dg(law, gap, c_loc(d))
  end function strata_law_dp_dg

  !> First-contact separation g0 = z_M - zbar (m).
  function strata_law_first_contact_gap(law, g0) result(code)
    type(c_ptr), intent(in) :: law
    real(c_double), intent(inout), target :: g0
    integer(c_int32_t) :: code
    code = c_strata_law_first_contact_gap(law, c_loc(g0))
  end function strata_law_first_contact_gap

  !> Smallest sampled separation g_min (m).
  function strata_law_min_gap(law, gmin) result(code)
    type(c_ptr), intent(in) :: law
    real(c_double), intent(inout), target :: gmin
    integer(c_int32_t) :: code
    code = c_strata_law_min_gap(law, c_loc(gmin))
  end function strata_law_min_gap

  !> Writes the sampled law to `path`: STRATA_FORMAT_CSV or STRATA_FORMAT_ABAQUS.
  function strata_law_write(law, path, format) result(code)
    type(c_ptr), intent(in) :: law
    character(*), intent(in) :: path
    integer(c_int32_t), intent(in) :: format
    integer(c_int32_t) :: code
    code = c_strata_law_write(law, c_path(path), format)
  end function strata_law_write

  !> Frees a law (c_null_ptr is a no-op) and sets the handle to c_null_ptr.
  subroutine strata_law_free(law)
    type(c_ptr), intent(inout) :: law
    call c_strata_law_free(law)
    law = c_null_ptr
  end subroutine strata_law_free

  !> A stack from arrays (top layer first): thickness (m), Young modulus (Pa), Poisson
  !> ratio of each layer, on a base STRATA_BASE_RIGID or STRATA_BASE_ELASTIC (then of
  !> base_young, base_poisson; with no layers the homogeneous half-space). The three
  !> arrays must have the same size (else STRATA_ERR_INVALID_ARGUMENT, no message); an
  !> error names the element, 0-based as in C (young[1] is young(2)).
  function strata_stack_new(thickness, young, poisson, base_kind, base_young, &
       base_poisson, stack) result(code)
    real(c_double), intent(in), target, contiguous :: thickness(:), young(:), poisson(:)
    integer(c_int32_t), intent(in) :: base_kind
    real(c_double), intent(in) :: base_young, base_poisson
    type(c_ptr), intent(out), target :: stack
    integer(c_int32_t) :: code
    stack = c_null_ptr
    if (size(young) /= size(thickness) .or. size(poisson) /= size(thickness)) then
       code = STRATA_ERR_INVALID_ARGUMENT
       return
    end if
    if (size(thickness) == 0) then
       code = c_strata_stack_new(0_c_size_t, c_null_ptr, c_null_ptr, c_null_ptr, &
            base_kind, base_young, base_poisson, c_loc(stack))
    else
       code = c_strata_stack_new(int(size(thickness), c_size_t), c_loc(thickness), &
            c_loc(young), c_loc(poisson), base_kind, base_young, base_poisson, c_loc(stack))
    end if
  end function strata_stack_new

  !> Frees a stack (c_null_ptr is a no-op) and sets the handle to c_null_ptr.
  subroutine strata_stack_free(stack)
    type(c_ptr), intent(inout) :: stack
    call c_strata_stack_free(stack)
    stack = c_null_ptr
  end subroutine strata_stack_free

  !> A surface from heights (m) in memory: nx*ny values with x the first (fast in C,
  !> here: heights(1 + j + i*ny) at x = i*dx, y = j*dy; an array h(ny, nx) in column
  !> order has this layout), pixel sizes dx, dy (m). The heights are copied.
  function strata_surface_new(heights, nx, ny, dx, dy, periodic, surface) result(code)
    real(c_double), intent(in), target, contiguous :: heights(:)
    integer, intent(in) :: nx, ny
    real(c_double), intent(in) :: dx, dy
    logical, intent(in) :: periodic
    type(c_ptr), intent(out), target :: surface
    integer(c_int32_t) :: code
    integer(c_int32_t) :: flag
    flag = 0
    if (periodic) flag = 1
    surface = c_null_ptr
    if (size(heights, kind=c_size_t) < int(nx, c_size_t) * int(ny, c_size_t)) then
       code = STRATA_ERR_INVALID_ARGUMENT
       return
    end if
    code = c_strata_surface_new(c_loc(heights), int(nx, c_size_t), int(ny, c_size_t), &
         dx, dy, flag, c_loc(surface))
  end function strata_surface_new

  !> strata_law_new_with_options on a stack handle (strata_stack_new) instead of a
  !> stack file; `options` optional (absent: the defaults).
  function strata_law_new_from_stack(table, stack, surface, model, min_gap, samples, law, &
       options) result(code)
    type(c_ptr), intent(in) :: table, stack, surface
    integer(c_int32_t), intent(in) :: model
    real(c_double), intent(in) :: min_gap
    integer, intent(in) :: samples
    type(c_ptr), intent(out), target :: law
    type(strata_solver_options), intent(in), target, optional :: options
    integer(c_int32_t) :: code
    type(c_ptr) :: opts
    opts = c_null_ptr
    if (present(options)) opts = c_loc(options)
    law = c_null_ptr
    code = c_strata_law_new_from_stack(table, stack, surface, model, min_gap, &
         int(samples, c_size_t), opts, c_loc(law))
  end function strata_law_new_from_stack

  !> p(g) (Pa), A(g)/A0 and dp/dg (Pa/m) at separation `gap` (m) in one call;
  !> unchanged on error.
  function strata_law_eval(law, gap, p, a, d) result(code)
    type(c_ptr), intent(in) :: law
    real(c_double), intent(in) :: gap
    real(c_double), intent(inout), target :: p, a, d
    integer(c_int32_t) :: code
    code = c_strata_law_eval(law, gap, c_loc(p), c_loc(a), c_loc(d))
  end function strata_law_eval

  !> strata_law_eval at every gaps(i) into p(i), a(i), d(i) (at least size(gaps) each,
  !> else STRATA_ERR_INVALID_ARGUMENT, no message); all or nothing.
  function strata_law_eval_array(law, gaps, p, a, d) result(code)
    type(c_ptr), intent(in) :: law
    real(c_double), intent(in), target, contiguous :: gaps(:)
    real(c_double), intent(inout), target, contiguous :: p(:), a(:), d(:)
    integer(c_int32_t) :: code
    if (size(p) < size(gaps) .or. size(a) < size(gaps) .or. size(d) < size(gaps)) then
       code = STRATA_ERR_INVALID_ARGUMENT
       return
    end if
    if (size(gaps) == 0) then
       code = c_strata_law_eval_array(law, 0_c_size_t, c_null_ptr, c_null_ptr, c_null_ptr, &
            c_null_ptr)
    else
       code = c_strata_law_eval_array(law, int(size(gaps), c_size_t), c_loc(gaps), c_loc(p), &
            c_loc(a), c_loc(d))
    end if
  end function strata_law_eval_array

  !> Reads a stack file (layers, base, [counterface], conductivities) into a handle.
  function strata_stack_load(path, stack) result(code)
    character(*), intent(in) :: path
    type(c_ptr), intent(out), target :: stack
    integer(c_int32_t) :: code
    stack = c_null_ptr
    code = c_strata_stack_load(c_path(path), c_loc(stack))
  end function strata_stack_load

  !> Sets the conductivities of `kind` (STRATA_CONDUCTANCE_THERMAL or _ELECTRICAL) on
  !> a stack: conductivity(i) of layer i (top first, one per layer; an empty array for
  !> a half-space), the base STRATA_BASE_CONDUCTION_HALF_SPACE (of base_conductivity)
  !> or STRATA_BASE_CONDUCTION_ISOTHERMAL. An error names the element, 0-based as in C.
  function strata_stack_set_conductivities(stack, kind, conductivity, base_conduction, &
       base_conductivity) result(code)
    type(c_ptr), intent(in) :: stack
    integer(c_int32_t), intent(in) :: kind, base_conduction
    real(c_double), intent(in), target, contiguous :: conductivity(:)
    real(c_double), intent(in) :: base_conductivity
    integer(c_int32_t) :: code
    if (size(conductivity) == 0) then
       code = c_strata_stack_set_conductivities(stack, kind, 0_c_size_t, c_null_ptr, &
            base_conduction, base_conductivity)
    else
       code = c_strata_stack_set_conductivities(stack, kind, &
            int(size(conductivity), c_size_t), c_loc(conductivity), base_conduction, &
            base_conductivity)
    end if
  end function strata_stack_set_conductivities

  !> The default law options (elastic, no conductance), `size` included.
  function strata_law_options_default(options) result(code)
    type(strata_law_options), intent(out), target :: options
    integer(c_int32_t) :: code
    code = c_strata_law_options_default(c_loc(options))
  end function strata_law_options_default

  !> The law of `surface` on the stack handle with the effects of `options` (a hardness:
  !> the capped N or I law; a conductance kind: h_c at every sample);
  !> `solver_options` optional (absent: the defaults).
  function strata_law_new_with_law_options(table, stack, surface, model, min_gap, &
       samples, options, law, solver_options) result(code)
    type(c_ptr), intent(in) :: table, stack, surface
    integer(c_int32_t), intent(in) :: model
    real(c_double), intent(in) :: min_gap
    integer, intent(in) :: samples
    type(strata_law_options), intent(in), target :: options
    type(c_ptr), intent(out), target :: law
    type(strata_solver_options), intent(in), target, optional :: solver_options
    integer(c_int32_t) :: code
    type(c_ptr) :: solver
    solver = c_null_ptr
    if (present(solver_options)) solver = c_loc(solver_options)
    law = c_null_ptr
    code = c_strata_law_new_with_law_options(table, stack, surface, model, min_gap, &
         int(samples, c_size_t), solver, c_loc(options), c_loc(law))
  end function strata_law_new_with_law_options

  !> The law's STRATA_CONDUCTANCE_* kind.
  function strata_law_conductance_kind(law, kind) result(code)
    type(c_ptr), intent(in) :: law
    integer(c_int32_t), intent(inout), target :: kind
    integer(c_int32_t) :: code
    code = c_strata_law_conductance_kind(law, c_loc(kind))
  end function strata_law_conductance_kind

  !> The hardness H (Pa) of a capped law (+Inf: elastic).
  function strata_law_hardness(law, h) result(code)
    type(c_ptr), intent(in) :: law
    real(c_double), intent(inout), target :: h
    integer(c_int32_t) :: code
    code = c_strata_law_hardness(law, c_loc(h))
  end function strata_law_hardness

  !> Full-stick tangential stiffness K_t of the sample (N/m) at separation `gap` (m), for
  !> a law built with options%friction_coefficient > 0.
  function strata_law_tangential_stiffness(law, gap, kt) result(code)
    type(c_ptr), intent(in) :: law
    real(c_double), intent(in) :: gap
    real(c_double), intent(inout), target :: kt
    integer(c_int32_t) :: code
    code = c_strata_law_tangential_stiffness(law, gap, c_loc(kt))
  end function strata_law_tangential_stiffness

  !> Interface conductance h_c(g) (W/(m^2 K) or S/m^2) at separation `gap` (m).
  function strata_law_conductance(law, gap, h) result(code)
    type(c_ptr), intent(in) :: law
    real(c_double), intent(in) :: gap
    real(c_double), intent(inout), target :: h
    integer(c_int32_t) :: code
    code = c_strata_law_conductance(law, gap, c_loc(h))
  end function strata_law_conductance

  !> h_c at every gaps(i) into h(i) (at least size(gaps), else
  !> STRATA_ERR_INVALID_ARGUMENT, no message); all or nothing.
  function strata_law_conductance_array(law, gaps, h) result(code)
    type(c_ptr), intent(in) :: law
    real(c_double), intent(in), target, contiguous :: gaps(:)
    real(c_double), intent(inout), target, contiguous :: h(:)
    integer(c_int32_t) :: code
    if (size(h) < size(gaps)) then
       code = STRATA_ERR_INVALID_ARGUMENT
       return
    end if
    if (size(gaps) == 0) then
       code = c_strata_law_conductance_array(law, 0_c_size_t, c_null_ptr, c_null_ptr)
    else
       code = c_strata_law_conductance_array(law, int(size(gaps), c_size_t), c_loc(gaps), &
            c_loc(h))
    end if
  end function strata_law_conductance_array

  !> h_c at mean contact pressure `pressure` (Pa): where p(g) reaches it on loading.
  function strata_law_conductance_at_pressure(law, pressure, h) result(code)
    type(c_ptr), intent(in) :: law
    real(c_double), intent(in) :: pressure
    real(c_double), intent(inout), target :: h
    integer(c_int32_t) :: code
    code = c_strata_law_conductance_at_pressure(law, pressure, c_loc(h))
  end function strata_law_conductance_at_pressure

  !> h_c at every pressures(i) into h(i); all or nothing.
  function strata_law_conductance_at_pressure_array(law, pressures, h) result(code)
    type(c_ptr), intent(in) :: law
    real(c_double), intent(in), target, contiguous :: pressures(:)
    real(c_double), intent(inout), target, contiguous :: h(:)
    integer(c_int32_t) :: code
    if (size(h) < size(pressures)) then
       code = STRATA_ERR_INVALID_ARGUMENT
       return
    end if
    if (size(pressures) == 0) then
       code = c_strata_law_conductance_at_pressure_array(law, 0_c_size_t, c_null_ptr, &
            c_null_ptr)
    else
       code = c_strata_law_conductance_at_pressure_array(law, &
            int(size(pressures), c_size_t), c_loc(pressures), c_loc(h))
    end if
  end function strata_law_conductance_at_pressure_array

  !> p (Pa), A/A0, dp/dg (Pa/m) and h_c at separation `gap` (m) in one call.
  function strata_law_eval_with_conductance(law, gap, p, a, d, h) result(code)
    type(c_ptr), intent(in) :: law
    real(c_double), intent(in) :: gap
    real(c_double), intent(inout), target :: p, a, d, h
    integer(c_int32_t) :: code
    code = c_strata_law_eval_with_conductance(law, gap, c_loc(p), c_loc(a), c_loc(d), &
         c_loc(h))
  end function strata_law_eval_with_conductance

end module strata
