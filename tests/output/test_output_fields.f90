!> Field output under MPI: writes a 2D (CPE4R) and a 3D (C3D8R) mesh with two frames of node
!> and element fields, as an interrupted run and its restart would:
!>   frame 0, then a "bogus" frame 1 (what the run wrote after its last checkpoint), close;
!>   reopen with restart_frames = 1 (frame 1 is dropped) and write the proper frame 1.
!> With 3 ranks the 2D mesh is spread over ranks 0 and 1 only, so rank 2 writes nothing and
!> must still take part. Values at nodes a rank does not own are garbage: only owners write.
!> check_output_fields.py then compares the files with the known values by global index.
!>   usage: test_output_fields <output base>   (writes <base>_2d.h5/.xmf, <base>_3d.h5/.xmf)
program test_output_fields
  use mpi_f08, only: MPI_Init, MPI_Finalize, MPI_COMM_WORLD, MPI_Comm_rank, MPI_Comm_size
  use material_kinds, only: dp
  use error_report, only: error_t
  use model_mesh, only: element_cpe4r, element_c3d8r
  use output_hdf5, only: field_writer_t, field_writer_open, field_writer_frame, &
       field_writer_end_frame, field_writer_coordinates, field_writer_node_field, &
       field_writer_element_field, field_writer_close, field_writer_frame_count
  use output_test_support, only: check, check_message, failures_everywhere, test_mesh_t, make_mesh
  implicit none

  character(len=512) :: base
  integer :: rank, nranks, failures

  call MPI_Init()
  call MPI_Comm_rank(MPI_COMM_WORLD, rank)
  call MPI_Comm_size(MPI_COMM_WORLD, nranks)
  call get_command_argument(1, base)
  if (len_trim(base) == 0) base = 'output_fields'

  if (nranks == 3) then
     call run_case(2, trim(base) // '_2d', 2)
  else
     call run_case(2, trim(base) // '_2d', nranks)
  end if
  call run_case(3, trim(base) // '_3d', nranks)

  failures = failures_everywhere()
  if (rank == 0) write (*, '(a, i0, a, i0)') 'test_output_fields: ranks ', nranks, &
       ', failed checks ', failures
  call MPI_Finalize()
  if (failures > 0) error stop 1

contains

  subroutine run_case(ndim, case_base, active)
    integer, intent(in) :: ndim
    character(len=*), intent(in) :: case_base
    integer, intent(in) :: active
    type(test_mesh_t) :: m
    type(field_writer_t) :: w
    type(error_t) :: err
    integer, allocatable :: node_id(:), elem_id(:)
    integer :: etype, g, e

    if (ndim == 2) then
       call make_mesh(2, 5, 4, 0, rank, active, m)
       etype = element_cpe4r
    else
       call make_mesh(3, 3, 2, 2, rank, active, m)
       etype = element_c3d8r
    end if
    allocate (node_id(m%n_nodes), elem_id(m%n_elems))
    node_id = [(100 + 3 * g, g = 1, m%n_nodes)]
    elem_id = [(1000 + 2 * e, e = 1, m%n_elems)]

    ! The run: frame 0, then frame 1 as it was before the interruption.
    call field_writer_open(w, case_base, MPI_COMM_WORLD, ndim, etype, m%n_nodes, m%n_elems, &
         m%node_global, m%node_owned, node_id(m%node_global), m%x0(:, m%node_global), &
         m%elem_global, elem_id(m%elem_global), m%conn(:, m%elem_global), err=err)
    call check(.not. err%raised, case_base // ': open')
    call write_frame(w, m, 0, .false.)
    call write_frame(w, m, 1, .true.)
    call check_errors(w, m, case_base)
    call check(field_writer_frame_count(w) == 2, case_base // ': frame count 2')
    call field_writer_close(w)

    ! The restart from a checkpoint taken after frame 0.
    call field_writer_open(w, case_base, MPI_COMM_WORLD, ndim, etype, m%n_nodes, m%n_elems, &
         m%node_global, m%node_owned, node_id(m%node_global), m%x0(:, m%node_global), &
         m%elem_global, elem_id(m%elem_global), m%conn(:, m%elem_global), restart_frames=1, &
         err=err)
    call check(.not. err%raised, case_base // ': reopen')
    call check(field_writer_frame_count(w) == 1, case_base // ': frame count 1 after reopen')
    call write_frame(w, m, 1, .false.)
    call field_writer_close(w)

    ! A restart asking for more frames than the file holds fails on every rank.
    call field_writer_open(w, case_base, MPI_COMM_WORLD, ndim, etype, m%n_nodes, m%n_elems, &
         m%node_global, m%node_owned, node_id(m%node_global), m%x0(:, m%node_global), &
         m%elem_global, elem_id(m%elem_global), m%conn(:, m%elem_global), restart_frames=5, &
         err=err)
    call check_message(err%raised, err%message, 'the file holds only 2 frames', &
         case_base // ': restart beyond the last frame')
  end subroutine run_case

  !> Frame f with the values check_output_fields.py expects (negated when bogus).
  subroutine write_frame(w, m, f, bogus)
    type(field_writer_t), intent(inout) :: w
    type(test_mesh_t), intent(in) :: m
    integer, intent(in) :: f
    logical, intent(in) :: bogus
    real(dp), allocatable :: u(:, :), rf(:, :), pnode(:, :), x(:, :), s(:, :), peeq(:, :)
    real(dp) :: sign
    integer :: i, c, g, e, ncomp_s, n

    sign = merge(-1.0_dp, 1.0_dp, bogus)
    n = size(m%node_global)
    ncomp_s = merge(4, 6, m%ndim == 2)
    allocate (u(m%ndim, n), rf(m%ndim, n), pnode(1, n), x(m%ndim, n))
    allocate (s(size(m%elem_global), ncomp_s), peeq(size(m%elem_global), 1))
    do i = 1, n
       g = m%node_global(i)
       do c = 1, m%ndim
          u(c, i) = sign * (g + 0.125_dp * c + 1000.0_dp * f)
          rf(c, i) = sign * (-0.5_dp * g * c + 0.25_dp * f)
       end do
       pnode(1, i) = sign * (0.25_dp * g + f)
       x(:, i) = m%x0(:, g) + u(:, i)
       if (.not. m%node_owned(i)) then
          ! Replicated copies must not reach the file.
          u(:, i) = -999.0_dp
          rf(:, i) = -999.0_dp
          pnode(:, i) = -999.0_dp
          x(:, i) = -999.0_dp
       end if
    end do
    do i = 1, size(m%elem_global)
       e = m%elem_global(i)
       do c = 1, ncomp_s
          s(i, c) = sign * (10.0_dp * e + c + 100.0_dp * f)
       end do
       peeq(i, 1) = sign * (e / 1024.0_dp + f)
    end do

    call field_writer_frame(w, 1 + f, 0.25_dp * f, 1.0_dp / 3.0_dp + 0.1_dp * f, 10 * f + 3)
    call field_writer_coordinates(w, m%node_global, m%node_owned, x)
    call field_writer_node_field(w, 'U', m%node_global, m%node_owned, u)
    call field_writer_node_field(w, 'RF', m%node_global, m%node_owned, rf)
    call field_writer_node_field(w, 'PNODE', m%node_global, m%node_owned, pnode)
    call field_writer_element_field(w, 'S', m%elem_global, s)
    call field_writer_element_field(w, 'PEEQ', m%elem_global, peeq)
    if (bogus) then
       call field_writer_node_field(w, 'BOGUS', m%node_global, m%node_owned, pnode)
    else
       call field_writer_end_frame(w)
    end if
  end subroutine write_frame

  !> Bad calls return the same error on every rank and leave the writer usable.
  subroutine check_errors(w, m, case_base)
    type(field_writer_t), intent(inout) :: w
    type(test_mesh_t), intent(in) :: m
    character(len=*), intent(in) :: case_base
    type(error_t) :: err
    real(dp), allocatable :: v(:, :)
    integer :: i

    allocate (v(m%ndim, size(m%node_global)))
    v = 0.0_dp
    call field_writer_node_field(w, 'a/b', m%node_global, m%node_owned, v, err)
    call check_message(err%raised, err%message, 'invalid field name', case_base // ': bad name')
    err = error_t()
    call field_writer_node_field(w, 'U', m%node_global, m%node_owned, v, err)
    call check_message(err%raised, err%message, 'field written twice', case_base // ': duplicate')
    if (nranks > 1) then
       deallocate (v)
       allocate (v(m%ndim + merge(0, 1, rank == 0), size(m%node_global)))
       v = 0.0_dp
       err = error_t()
       call field_writer_node_field(w, 'W', m%node_global, m%node_owned, v, err)
       call check_message(err%raised, err%message, 'ranks disagree on the number of components', &
            case_base // ': component counts differ')
    end if
    err = error_t()
    call field_writer_element_field(w, 'E', m%elem_global(size(m%elem_global):1:-1), &
         reshape([(1.0_dp, i = 1, size(m%elem_global))], [size(m%elem_global), 1]), err)
    ! Some rank has several elements, so every rank gets the error.
    call check_message(err%raised, err%message, 'must be strictly ascending', &
         case_base // ': descending elements')
  end subroutine check_errors

end program test_output_fields
