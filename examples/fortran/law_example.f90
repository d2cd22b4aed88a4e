! strata Fortran example: the twin of examples/c/law_example.c through the module
! capi/fortran/strata.f90. The contact law of the paper's rough surface on the
! two-layer stack E2/E1 = 1, interacting asperities (I model, periodic images).
!
! Build (from the repository root, after `cargo build -p strata-capi`):
!   gfortran -std=f2008 capi/fortran/strata.f90 examples/fortran/law_example.f90 \
!     -L target/debug -lstrata_capi -Wl,-rpath,$PWD/target/debug -o law_example_f
!   ./law_example_f tables/paper-two-layer.strata tables/stacks/paper-two-layer-E2E1-1.toml
!
! Prints p(g) (Pa), A(g)/A0 and dp/dg (Pa/m) at a few separations g (m) with 17
! significant digits (exact round trip), then shows how errors are reported. SI units.
! capi/tests/c_example.rs builds and runs it and checks that every number equals the
! C example's bit for bit and every error line is the same.
program law_example
  use, intrinsic :: ieee_arithmetic, only: ieee_quiet_nan, ieee_value
  use, intrinsic :: iso_fortran_env, only: error_unit
  use strata
  implicit none

  character(:), allocatable :: table_path, stack_path, model_text
  integer(c_int32_t) :: model
  type(c_ptr) :: table, surface, law, missing, other
  real(c_double) :: g0, gmin, gaps(12), p, a, d, v
  integer :: n, k, i

  table_path = argument(1, "tables/paper-two-layer.strata")
  stack_path = argument(2, "tables/stacks/paper-two-layer-E2E1-1.toml")
  model = STRATA_MODEL_INTERACTING_PERIODIC
  if (command_argument_count() > 2) then
     model_text = argument(3, "")
     read (model_text, *) model
  end if

  write (*, '(a)') "strata " // strata_version()
  call check(strata_table_load(table_path, table), "strata_table_load")
  ! The paper's surface (scenes/paper-E2E1-1-*.toml): L = 1 mm, 512 x 512,
  ! D_f = 2.4, k = 2..10, RMS 3.4 um, seed 20240611.
  call check(strata_surface_generate(1d-3, 512, 2.4d0, 2d0, 10d0, 3.4d-6, &
       20240611_c_int64_t, surface), "strata_surface_generate")
  ! 200 samples from first contact down to g = 1 um.
  call check(strata_law_new(table, stack_path, surface, model, 1d-6, 200, law), &
       "strata_law_new")

  g0 = 0
  gmin = 0
  call check(strata_law_first_contact_gap(law, g0), "strata_law_first_contact_gap")
  call check(strata_law_min_gap(law, gmin), "strata_law_min_gap")
  write (*, '(a,1x,es24.16e3)') "first_contact_gap", g0
  write (*, '(a,1x,es24.16e3)') "min_gap", gmin

  ! Above first contact, at it, inside (not on the samples), at the bottom; the same
  ! floating-point operations in the same order as the C example.
  n = 0
  n = n + 1
  gaps(n) = g0 + 1d-7
  n = n + 1
  gaps(n) = g0
  do k = 1, 9
     n = n + 1
     gaps(n) = g0 - ((g0 - gmin) * (real(k, c_double) - 0.3d0)) / 9d0
  end do
  n = n + 1
  gaps(n) = gmin

  write (*, '(a)') "# gap pressure area_fraction dp_dg"
  do i = 1, n
     call check(strata_law_pressure(law, gaps(i), p), "strata_law_pressure")
     call check(strata_law_area_fraction(law, gaps(i), a), "strata_law_area_fraction")
     call check(strata_law_dp_dg(law, gaps(i), d), "strata_law_dp_dg")
     write (*, '(a,4(1x,es24.16e3))') "point", gaps(i), p, a, d
  end do

  ! Errors come back as codes with a message; nothing aborts.
  call expect_error("nan_gap", strata_law_pressure(law, ieee_value(v, ieee_quiet_nan), v))
  call expect_error("below_range", strata_law_pressure(law, gmin - 1d-7, v))
  call expect_error("null_out", c_strata_law_dp_dg(law, gmin, c_null_ptr))
  call expect_error("null_law", strata_law_area_fraction(c_null_ptr, gmin, v))
  call expect_error("missing_table", strata_table_load("no/such/table.strata", missing))
  call expect_error("layered_without_table", &
       strata_law_new(c_null_ptr, stack_path, surface, model, 1d-6, 200, other))
  call expect_error("bad_model", strata_law_new(table, stack_path, surface, 7, 1d-6, 200, other))
  call expect_error("min_gap_above_contact", &
       strata_law_new(table, stack_path, surface, model, g0 + 1d-6, 200, other))
  ! Absurd sizes are refused before anything is allocated (cap STRATA_MAX_SAMPLES);
  ! -1 reaches C as SIZE_MAX.
  call expect_error("samples_1e9", &
       strata_law_new(table, stack_path, surface, model, 1d-6, 1000000000, other))
  call expect_error("samples_size_max", &
       strata_law_new(table, stack_path, surface, model, 1d-6, -1, other))

  call strata_law_free(law)
  call strata_surface_free(surface)
  call strata_table_free(table)

contains

  !> Command-line argument `i`, or `default` when absent.
  function argument(i, default) result(s)
    integer, intent(in) :: i
    character(*), intent(in) :: default
    character(:), allocatable :: s
    integer :: length
    if (command_argument_count() < i) then
       s = default
       return
    end if
    call get_command_argument(i, length=length)
    allocate (character(len=length) :: s)
    call get_command_argument(i, s)
  end function argument

  !> Stops with the message when `code` is not STRATA_OK.
  subroutine check(code, what)
    integer(c_int32_t), intent(in) :: code
    character(*), intent(in) :: what
    if (code /= STRATA_OK) then
       write (error_unit, '(a,a,i0,a,a)') what, " failed (code ", code, "): ", &
            strata_last_error_message()
       error stop 1
    end if
  end subroutine check

  !> Prints the code and message of a call expected to fail.
  subroutine expect_error(name, code)
    character(*), intent(in) :: name
    integer(c_int32_t), intent(in) :: code
    if (code == STRATA_OK) then
       write (*, '(a,1x,a,1x,i0,1x,a)') "error", name, code, "(no error)"
    else
       write (*, '(a,1x,a,1x,i0,1x,a)') "error", name, code, strata_last_error_message()
    end if
  end subroutine expect_error

end program law_example
