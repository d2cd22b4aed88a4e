! strata Fortran example from memory: the twin of examples/c/memory_example.c through
! the module capi/fortran/strata.f90. A stack from arrays, a surface from a height
! array, p, A/A0 and dp/dg in one call (scalar and array); no stack or surface file.
!
! Build (from the repository root, after `cargo build -p strata-capi`):
!   gfortran -std=f2008 capi/fortran/strata.f90 examples/fortran/memory_example.f90 \
!     -L target/debug -lstrata_capi -Wl,-rpath,$PWD/target/debug -o memory_example_f
!   ./memory_example_f TABLE STACK.toml HEIGHTS.bin N L
! (arguments as for the C example). capi/tests/c_example.rs checks that it prints the
! C example's lines, every number bit for bit.
program memory_example
  use, intrinsic :: ieee_arithmetic, only: ieee_quiet_nan, ieee_value
  use, intrinsic :: iso_c_binding, only: c_loc
  use, intrinsic :: iso_fortran_env, only: error_unit
  use strata
  implicit none

  integer(c_int32_t), parameter :: model = STRATA_MODEL_INTERACTING_PERIODIC
  character(:), allocatable :: table_path, stack_path, heights_path, text
  integer :: n, i, k, unit, status
  real(c_double) :: size, dx, g0, gmin, kept
  real(c_double), target :: p, a, d
  real(c_double), allocatable :: heights(:)
  real(c_double) :: gaps(12), ap(12), aa(12), ad(12), bad_gaps(3)
  real(c_double), target :: op(3), oa(3), od(3)
  real(c_double), target :: none(1)
  type(c_ptr) :: table, surface, stack, from_file, from_memory, other
  type(c_ptr), target :: bad, other_surface

  table_path = argument(1)
  stack_path = argument(2)
  heights_path = argument(3)
  text = argument(4)
  read (text, *) n
  text = argument(5)
  read (text, *) size

  write (*, '(a,3(1x,i0),1x,a)') "version", STRATA_VERSION_MAJOR, STRATA_VERSION_MINOR, &
       STRATA_VERSION_PATCH, strata_version()

  ! The heights: n*n doubles, x the first (slow) index, as the C example reads them.
  allocate (heights(n * n))
  open (newunit=unit, file=heights_path, access="stream", form="unformatted", &
       status="old", action="read", iostat=status)
  if (status /= 0) then
     write (error_unit, '(a,a)') "cannot open ", heights_path
     error stop 1
  end if
  read (unit) heights
  close (unit)

  call check(strata_table_load(table_path, table), "strata_table_load")
  dx = size / real(n, c_double)
  call check(strata_surface_new(heights, n, n, dx, dx, .true., surface), "strata_surface_new")
  ! The stack file's values: 100 um of E = 4 GPa on 900 um of E = 4 GPa, rigid base.
  call check(strata_stack_new([100d-6, 900d-6], [4d9, 4d9], [0.15d0, 0.15d0], &
       STRATA_BASE_RIGID, 0d0, 0d0, stack), "strata_stack_new")
  call check(strata_law_new(table, stack_path, surface, model, 1d-6, 50, from_file), &
       "strata_law_new")
  call check(strata_law_new_from_stack(table, stack, surface, model, 1d-6, 50, from_memory), &
       "strata_law_new_from_stack")

  g0 = 0
  gmin = 0
  call check(strata_law_first_contact_gap(from_memory, g0), "strata_law_first_contact_gap")
  call check(strata_law_min_gap(from_memory, gmin), "strata_law_min_gap")
  ! The same floating-point operations in the same order as the C example.
  gaps(1) = g0 + 1d-7
  gaps(2) = g0
  do k = 1, 9
     gaps(2 + k) = g0 - ((g0 - gmin) * (real(k, c_double) - 0.3d0)) / 9d0
  end do
  gaps(12) = gmin

  call check(strata_law_eval_array(from_memory, gaps, ap, aa, ad), "strata_law_eval_array")
  do i = 1, 12
     call check(strata_law_pressure(from_file, gaps(i), p), "strata_law_pressure")
     call check(strata_law_area_fraction(from_file, gaps(i), a), "strata_law_area_fraction")
     call check(strata_law_dp_dg(from_file, gaps(i), d), "strata_law_dp_dg")
     write (*, '(a,4(1x,es24.16e3))') "point", gaps(i), p, a, d
     call check(strata_law_eval(from_memory, gaps(i), p, a, d), "strata_law_eval")
     write (*, '(a,4(1x,es24.16e3))') "memory", gaps(i), p, a, d
     write (*, '(a,4(1x,es24.16e3))') "array", gaps(i), ap(i), aa(i), ad(i)
  end do

  ! Bad input: a code and a message naming the argument; nothing aborts.
  call expect_error("stack_negative_young", strata_stack_new([100d-6, 900d-6], &
       [4d9, -1d0], [0.15d0, 0.15d0], STRATA_BASE_RIGID, 0d0, 0d0, bad))
  call expect_error("stack_nan_thickness", strata_stack_new( &
       [ieee_value(p, ieee_quiet_nan), 900d-6], [4d9, 4d9], [0.15d0, 0.15d0], &
       STRATA_BASE_RIGID, 0d0, 0d0, bad))
  none(1) = 0
  call expect_error("stack_null_young", c_strata_stack_new(2_c_size_t, c_loc(none), &
       c_null_ptr, c_loc(none), STRATA_BASE_RIGID, 0d0, 0d0, c_loc(bad)))
  call expect_error("stack_bad_base_kind", strata_stack_new([100d-6, 900d-6], &
       [4d9, 4d9], [0.15d0, 0.15d0], 5, 0d0, 0d0, bad))
  call expect_error("stack_rigid_without_layers", strata_stack_new(none(1:0), none(1:0), &
       none(1:0), STRATA_BASE_RIGID, 0d0, 0d0, bad))
  call expect_error("stack_bad_base_poisson", strata_stack_new(none(1:0), none(1:0), &
       none(1:0), STRATA_BASE_ELASTIC, 4d9, 0.7d0, bad))
  call expect_error("surface_null_heights", c_strata_surface_new(c_null_ptr, &
       int(n, c_size_t), int(n, c_size_t), dx, dx, 1, c_loc(other_surface)))
  call expect_error("surface_zero_dx", strata_surface_new(heights, n, n, 0d0, dx, .true., &
       other_surface))
  call expect_error("surface_too_small", strata_surface_new(heights, 2, 2, dx, dx, .true., &
       other_surface))
  kept = heights(6)
  heights(6) = ieee_value(p, ieee_quiet_nan)
  call expect_error("surface_nan_height", strata_surface_new(heights, n, n, dx, dx, .true., &
       other_surface))
  heights(6) = kept
  call expect_error("law_null_stack", strata_law_new_from_stack(table, c_null_ptr, surface, &
       model, 1d-6, 50, other))
  call expect_error("eval_null_area", c_strata_law_eval(from_memory, gmin, c_loc(p), &
       c_null_ptr, c_loc(d)))
  call expect_error("eval_below_range", strata_law_eval(from_memory, gmin - 1d-7, p, a, d))
  ! All or nothing: one gap out of range leaves the outputs as they were.
  bad_gaps = [g0, gmin - 1d-7, gmin]
  op = -1
  oa = -1
  od = -1
  call expect_error("eval_array_below_range", &
       strata_law_eval_array(from_memory, bad_gaps, op, oa, od))
  if (minus_one(op(1)) .and. minus_one(oa(1)) .and. minus_one(od(3))) then
     write (*, '(a)') "untouched 1"
  else
     write (*, '(a)') "untouched 0"
  end if
  call expect_error("eval_array_null_gaps", c_strata_law_eval_array(from_memory, &
       3_c_size_t, c_null_ptr, c_loc(op), c_loc(oa), c_loc(od)))
  call expect_error("eval_array_empty", strata_law_eval_array(from_memory, none(1:0), &
       none(1:0), none(1:0), none(1:0)))

  call strata_law_free(from_memory)
  call strata_law_free(from_file)
  call strata_stack_free(stack)
  call strata_surface_free(surface)
  call strata_table_free(table)

contains

  !> Whether `x` is exactly -1 (as C's `x == -1`, without -Wcompare-reals).
  logical function minus_one(x)
    real(c_double), intent(in) :: x
    minus_one = .not. (x < -1d0 .or. x > -1d0)
  end function minus_one

  !> Command-line argument `i` (required).
  function argument(i) result(s)
    integer, intent(in) :: i
    character(:), allocatable :: s
    integer :: length
    if (command_argument_count() < i) then
       write (error_unit, '(a)') "usage: memory_example_f TABLE STACK.toml HEIGHTS.bin N L"
       error stop 2
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

end program memory_example
