! strata Fortran example: the twin of examples/c/effects_example.c through the module
! capi/fortran/strata.f90. The contact law's two effects: yielding asperity tips (a
! hardness) and the interface conductance.
!
! Build (from the repository root, after `cargo build -p strata-capi`):
!   gfortran -std=f2008 capi/fortran/strata.f90 examples/fortran/effects_example.f90 \
!     -L target/debug -lstrata_capi -Wl,-rpath,$PWD/target/debug -o effects_example_f
!   ./effects_example_f tables/paper-two-layer.strata \
!     tables/stacks/paper-two-layer-conducting.toml OUT_DIR
!
! Prints the lines of the C example (numbers with 17 significant digits, an exact round
! trip) and writes the same CSV files; capi/tests/c_example.rs checks that every number
! equals the C example's bit for bit and every error line is the same. SI units.
program effects_example
  use, intrinsic :: ieee_arithmetic, only: ieee_positive_inf, ieee_value
  use, intrinsic :: iso_fortran_env, only: error_unit
  use strata
  implicit none

  integer, parameter :: samples = 8
  character(:), allocatable :: table_path, stack_path, out_dir
  type(c_ptr) :: table, half, rough, capped, inf, elastic, conducting, paper, li, ln, &
       memory, from_memory, from_file, other, plain, half_k, cc
  type(strata_law_options) :: o, th, el, bad, ct
  integer(c_int32_t) :: models(2), kind
  real(c_double) :: h, gaps(samples), p, a, d, p2, a2, d2, g, v, gmin, h1, h2
  real(c_double) :: k(2), bad_k(2)
  integer :: m, i, j

  table_path = argument(1)
  stack_path = argument(2)
  out_dir = argument(3)
  call check(strata_table_load(table_path, table), "strata_table_load")

  ! 1. Capped tips on a half-space (no table needed).
  call check(strata_stack_new([real(c_double) ::], [real(c_double) ::], [real(c_double) ::], &
       STRATA_BASE_ELASTIC, 4d9, 0.15d0, half), "strata_stack_new")
  call check(strata_surface_generate(1d-3, 128, 2.4d0, 2d0, 6d0, 3.4d-6, 5_c_int64_t, rough), &
       "strata_surface_generate")
  models = [STRATA_MODEL_INDEPENDENT, STRATA_MODEL_INTERACTING_PERIODIC]
  do m = 1, 2
     call check(strata_law_options_default(o), "strata_law_options_default")
     o%hardness = 0.2d9
     call check(strata_law_new_with_law_options(c_null_ptr, half, rough, models(m), 0d0, &
          samples, o, capped), "strata_law_new_with_law_options (hardness)")
     call check(strata_law_hardness(capped, h), "strata_law_hardness")
     write (*, '(a,1x,i0,1x,es24.16e3)') "hardness", models(m), h
     call check(strata_law_write(capped, out_dir // "/capped-" // itoa(models(m)) // ".csv", &
          STRATA_FORMAT_CSV), "strata_law_write")
     call sample_gaps(capped, gaps)
     do i = 1, samples
        call check(strata_law_eval(capped, gaps(i), p, a, d), "strata_law_eval")
        write (*, '(a,1x,i0,3(1x,es24.16e3))') "capped", models(m), gaps(i), p, a
     end do
     o%hardness = ieee_value(o%hardness, ieee_positive_inf)
     call check(strata_law_new_with_law_options(c_null_ptr, half, rough, models(m), 0d0, &
          samples, o, inf), "strata_law_new_with_law_options (INFINITY)")
     call check(strata_law_new_from_stack(c_null_ptr, half, rough, models(m), 0d0, samples, &
          elastic), "strata_law_new_from_stack")
     call check(strata_law_hardness(inf, h), "strata_law_hardness")
     write (*, '(a,1x,i0,1x,es24.16e3)') "hardness_infinity", models(m), h
     do i = 1, samples - 1
        do j = 0, 1
           if (j == 0) then
              g = gaps(i)
           else
              g = 0.5d0 * (gaps(i) + gaps(i + 1))
           end if
           call check(strata_law_eval(inf, g, p, a, d), "strata_law_eval")
           call check(strata_law_eval(elastic, g, p2, a2, d2), "strata_law_eval")
           write (*, '(a,1x,i0,7(1x,es24.16e3))') "infinity_vs_elastic", models(m), g, p, p2, &
                a, a2, d, d2
        end do
     end do
     call strata_law_free(elastic)
     call strata_law_free(inf)
     call strata_law_free(capped)
  end do

  ! 2. Conductance on the paper's stack with conductivities (stack file).
  call check(strata_stack_load(stack_path, conducting), "strata_stack_load")
  call check(strata_surface_generate(1d-3, 128, 2.4d0, 2d0, 10d0, 3.4d-6, &
       20240611_c_int64_t, paper), "strata_surface_generate")
  call check(strata_law_options_default(th), "strata_law_options_default")
  th%conductance_kind = STRATA_CONDUCTANCE_THERMAL
  th%counterface_conduction = STRATA_COUNTERFACE_CONDUCTION_HALF_SPACE
  th%counterface_conductivity = 50d0  ! a steel flat, W/(m K)
  call check(strata_law_new_with_law_options(table, conducting, paper, &
       STRATA_MODEL_INTERACTING_PERIODIC, 2d-6, samples, th, li), &
       "strata_law_new_with_law_options (thermal, I model)")
  kind = -1
  call check(strata_law_conductance_kind(li, kind), "strata_law_conductance_kind")
  write (*, '(a,1x,i0)') "conductance_kind thermal", kind
  call check(strata_law_write(li, out_dir // "/conductance-" // &
       itoa(STRATA_MODEL_INTERACTING_PERIODIC) // ".csv", STRATA_FORMAT_CSV), "strata_law_write")
  call print_conductance("thermal_i", li)

  call check(strata_law_options_default(el), "strata_law_options_default")
  el%conductance_kind = STRATA_CONDUCTANCE_ELECTRICAL
  el%counterface_conduction = STRATA_COUNTERFACE_CONDUCTION_PERFECT
  call check(strata_law_new_with_law_options(table, conducting, paper, &
       STRATA_MODEL_INDEPENDENT, 2d-6, samples, el, ln), &
       "strata_law_new_with_law_options (electrical, N model)")
  call check(strata_law_conductance_kind(ln, kind), "strata_law_conductance_kind")
  write (*, '(a,1x,i0)') "conductance_kind electrical", kind
  call check(strata_law_write(ln, out_dir // "/conductance-" // &
       itoa(STRATA_MODEL_INDEPENDENT) // ".csv", STRATA_FORMAT_CSV), "strata_law_write")
  call print_conductance("electrical_n", ln)

  ! The same stack from arrays: thermal conductivities 0.5 and 5 W/(m K) on an
  ! isothermal base (tables/stacks/paper-two-layer-conducting.toml).
  k = [0.5d0, 5d0]
  call check(strata_stack_new([100d-6, 900d-6], [4d9, 20d9], [0.15d0, 0.15d0], &
       STRATA_BASE_RIGID, 0d0, 0d0, memory), "strata_stack_new")
  call check(strata_stack_set_conductivities(memory, STRATA_CONDUCTANCE_THERMAL, k, &
       STRATA_BASE_CONDUCTION_ISOTHERMAL, 0d0), "strata_stack_set_conductivities")
  call check(strata_law_new_with_law_options(table, memory, paper, STRATA_MODEL_INDEPENDENT, &
       2d-6, samples, th, from_memory), "strata_law_new_with_law_options (memory stack)")
  call check(strata_law_new_with_law_options(table, conducting, paper, &
       STRATA_MODEL_INDEPENDENT, 2d-6, samples, th, from_file), &
       "strata_law_new_with_law_options (file stack)")
  call sample_gaps(from_file, gaps)
  do i = 1, samples
     call check(strata_law_conductance(from_memory, gaps(i), h1), "strata_law_conductance")
     call check(strata_law_conductance(from_file, gaps(i), h2), "strata_law_conductance")
     write (*, '(a,3(1x,es24.16e3))') "memory_vs_file", gaps(i), h1, h2
  end do

  ! Capped tips that conduct: the half-space of section 1 with a thermal conductivity of
  ! 0.5 W/(m K), hardness 0.2 GPa, against the steel flat: h_c of the capped spots.
  call check(strata_stack_new([real(c_double) ::], [real(c_double) ::], [real(c_double) ::], &
       STRATA_BASE_ELASTIC, 4d9, 0.15d0, half_k), "strata_stack_new")
  call check(strata_stack_set_conductivities(half_k, STRATA_CONDUCTANCE_THERMAL, &
       [real(c_double) ::], STRATA_BASE_CONDUCTION_HALF_SPACE, 0.5d0), &
       "strata_stack_set_conductivities")
  do m = 1, 2
     ct = th  ! thermal, the steel flat
     ct%hardness = 0.2d9
     call check(strata_law_new_with_law_options(c_null_ptr, half_k, rough, models(m), 0d0, &
          samples, ct, cc), "strata_law_new_with_law_options (hardness, thermal)")
     call check(strata_law_write(cc, out_dir // "/capped-conductance-" // itoa(models(m)) // &
          ".csv", STRATA_FORMAT_CSV), "strata_law_write")
     if (m == 1) then
        call print_conductance("capped_n", cc)
     else
        call print_conductance("capped_i", cc)
     end if
     call strata_law_free(cc)
  end do
  call strata_stack_free(half_k)

  ! 3. Bad options come back as codes with a message naming the field.
  v = 0
  gmin = 0
  call check(strata_law_min_gap(li, gmin), "strata_law_min_gap")
  call check(strata_law_options_default(bad), "strata_law_options_default")
  bad%hardness = -1d0
  call expect_error("negative_hardness", strata_law_new_with_law_options(c_null_ptr, half, &
       rough, STRATA_MODEL_INDEPENDENT, 0d0, samples, bad, other))
  call check(strata_law_options_default(bad), "strata_law_options_default")
  bad%conductance_kind = 7
  call expect_error("unknown_kind", strata_law_new_with_law_options(c_null_ptr, half, &
       rough, STRATA_MODEL_INDEPENDENT, 0d0, samples, bad, other))
  call check(strata_law_options_default(bad), "strata_law_options_default")
  bad%conductance_kind = STRATA_CONDUCTANCE_THERMAL
  bad%counterface_conduction = STRATA_COUNTERFACE_CONDUCTION_PERFECT
  call expect_error("missing_conductivity", strata_law_new_with_law_options(c_null_ptr, &
       half, rough, STRATA_MODEL_INDEPENDENT, 0d0, samples, bad, other))
  bad%counterface_conduction = STRATA_COUNTERFACE_CONDUCTION_STACK
  call expect_error("rigid_flat_conduction_unset", strata_law_new_with_law_options(table, &
       conducting, paper, STRATA_MODEL_INDEPENDENT, 2d-6, samples, bad, other))
  bad%counterface_conduction = STRATA_COUNTERFACE_CONDUCTION_HALF_SPACE
  bad%counterface_conductivity = -50d0
  call expect_error("negative_counterface_conductivity", &
       strata_law_new_with_law_options(table, conducting, paper, STRATA_MODEL_INDEPENDENT, &
       2d-6, samples, bad, other))
  call check(strata_law_options_default(bad), "strata_law_options_default")
  bad%size = 0
  call expect_error("options_not_initialised", strata_law_new_with_law_options(c_null_ptr, &
       half, rough, STRATA_MODEL_INDEPENDENT, 0d0, samples, bad, other))
  bad_k = [0.5d0, -1d0]
  call expect_error("negative_layer_conductivity", strata_stack_set_conductivities(memory, &
       STRATA_CONDUCTANCE_THERMAL, bad_k, STRATA_BASE_CONDUCTION_ISOTHERMAL, 0d0))
  call expect_error("wrong_layer_count", strata_stack_set_conductivities(memory, &
       STRATA_CONDUCTANCE_THERMAL, k(1:1), STRATA_BASE_CONDUCTION_ISOTHERMAL, 0d0))
  call expect_error("conductance_below_range", strata_law_conductance(li, gmin - 1d-7, v))
  call check(strata_law_new_from_stack(table, conducting, paper, STRATA_MODEL_INDEPENDENT, &
       2d-6, samples, plain), "strata_law_new_from_stack")
  call expect_error("no_conductance_in_law", strata_law_conductance(plain, gmin, v))
  call strata_law_free(plain)
  call expect_error("pressure_above_samples", strata_law_conductance_at_pressure(li, 1d12, v))

  call strata_law_free(from_file)
  call strata_law_free(from_memory)
  call strata_law_free(ln)
  call strata_law_free(li)
  call strata_stack_free(memory)
  call strata_stack_free(conducting)
  call strata_stack_free(half)
  call strata_surface_free(paper)
  call strata_surface_free(rough)
  call strata_table_free(table)

contains

  !> Command-line argument `i` (required).
  function argument(i) result(s)
    integer, intent(in) :: i
    character(:), allocatable :: s
    integer :: length
    if (command_argument_count() < i) then
       write (error_unit, '(a)') &
            "usage: effects_example_f TABLE CONDUCTING_STACK OUT_DIR"
       error stop 2
    end if
    call get_command_argument(i, length=length)
    allocate (character(len=length) :: s)
    call get_command_argument(i, s)
  end function argument

  !> An integer in decimal.
  function itoa(n) result(s)
    integer(c_int32_t), intent(in) :: n
    character(:), allocatable :: s
    character(32) :: buffer
    write (buffer, '(i0)') n
    s = trim(buffer)
  end function itoa

  !> The law's sample separations, with the floating-point operations of the library's
  !> sampling (as the C example).
  subroutine sample_gaps(law, out)
    type(c_ptr), intent(in) :: law
    real(c_double), intent(out) :: out(samples)
    real(c_double) :: g0, gm
    integer :: n
    g0 = 0
    gm = 0
    call check(strata_law_first_contact_gap(law, g0), "strata_law_first_contact_gap")
    call check(strata_law_min_gap(law, gm), "strata_law_min_gap")
    do n = 1, samples
       if (n == samples) then
          out(n) = gm
       else
          out(n) = g0 - ((g0 - gm) * real(n - 1, c_double)) / real(samples - 1, c_double)
       end if
    end do
  end subroutine sample_gaps

  !> h_c(g), h_c(p(g)) and the combined eval at the samples and half-way between them.
  subroutine print_conductance(label, law)
    character(*), intent(in) :: label
    type(c_ptr), intent(in) :: law
    real(c_double) :: s(samples), at(2 * samples - 1), hs(2 * samples - 1)
    real(c_double) :: pp, aa, dd, hc, hg, hp
    integer :: n
    call sample_gaps(law, s)
    do n = 1, samples - 1
       at(2 * n - 1) = s(n)
       at(2 * n) = 0.5d0 * (s(n) + s(n + 1))
    end do
    at(2 * samples - 1) = s(samples)
    call check(strata_law_conductance_array(law, at, hs), "strata_law_conductance_array")
    do n = 1, 2 * samples - 1
       call check(strata_law_eval_with_conductance(law, at(n), pp, aa, dd, hc), &
            "strata_law_eval_with_conductance")
       call check(strata_law_conductance(law, at(n), hg), "strata_law_conductance")
       call check(strata_law_conductance_at_pressure(law, pp, hp), &
            "strata_law_conductance_at_pressure")
       write (*, '(a,1x,a,6(1x,es24.16e3))') "conductance", label, at(n), pp, hc, hg, &
            hs(n), hp
    end do
  end subroutine print_conductance

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

end program effects_example
