!> bulkflow-scene-check: reads a scene with the scene reader and nothing else.
!> A bad scene ends like every bulkflow input error: `bulkflow: error: file:line: ...` on
!> stderr and exit status 2 (error_report's final stop, no backtrace); a good one prints a
!> one-line summary. The bad-input suite runs it until `bulkflow --check` takes over.
!>
!>   bulkflow-scene-check [--user-subroutine] scene.inp
program scene_check
  use, intrinsic :: iso_fortran_env, only: error_unit
  use error_report, only: error_t, fatal_error
  use model, only: model_t
  use scene_reader, only: read_scene
  implicit none
  type(model_t) :: model
  type(error_t) :: err
  character(len=:), allocatable :: path, arg
  logical :: user
  integer :: i, n

  user = .false.
  do i = 1, command_argument_count()
     call get_command_argument(i, length=n)
     allocate (character(len=n) :: arg)
     call get_command_argument(i, arg)
     if (arg == '--user-subroutine') then
        user = .true.
     else if (.not. allocated(path)) then
        path = arg
     else
        write (error_unit, '(a)') 'usage: bulkflow-scene-check [--user-subroutine] scene.inp'
        error stop 2
     end if
     deallocate (arg)
  end do
  if (.not. allocated(path)) then
     write (error_unit, '(a)') 'usage: bulkflow-scene-check [--user-subroutine] scene.inp'
     error stop 2
  end if
  call read_scene(path, model, err, user_subroutine=user)
  if (err%raised) call fatal_error(err)
  write (*, '(a, i0, a, i0, a, i0, a, i0, a)') 'scene ok: ', model%mesh%n_nodes, ' nodes, ', &
       model%mesh%n_elems, ' elements, ', model%n_materials, ' materials, ', model%n_steps, ' steps'
end program scene_check
