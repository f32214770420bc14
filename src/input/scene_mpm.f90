!> The material-point keywords of a scene (bulkflow's own; docs/keywords.md, section "MPM"):
!>
!>   *MPM GRID, CELL=h [, SHAPE=GIMP|LINEAR]        data: lo corner; hi corner (2 or 3 values)
!>   *MPM CONTROLS [, FLIP=α | PIC TIME=τ] [, CFL=c] [, DAMPING=a] [, SORT=n] [, MAX DILATION=j]
!>                                                  model data or in a step; carries over
!>     [, DECOMPOSITION=REPLICATED|SPATIAL] [, REBALANCE=r]   model data only (MPI ranks)
!>   *MPM SIDE FRICTION, GAP=t, FRICTION=μw         2D, model data or in a step; carries over
!>   *PARTICLES, MATERIAL=name [, PPC=n] [, TYPE=BOX|POLYGON] [, Z1=, Z2=] [, VX=, VY=, VZ=]
!>                                                  data: BOX lo; hi  |  POLYGON x, y per line
!>   *MPM WALL, NAME=w [, TYPE=FRICTION|SYMMETRY] [, FRICTION=μ] [, REACH=r] [, OPEN=START|END|BOTH]
!>     [, OPEN=XLOW|...|ZHIGH (3D)] [, OP=DELETE]   OPEN: scene_mpm_wall_open
!>                                                  data 2D: x0, y0, x1, y1 (material on the left)
!>                                                  data 3D: px, py, pz, nx, ny, nz [; lo; hi]
!>   *OUTFLOW, BELOW=y                              model data: particles below y leave
!>   *INFLOW, MATERIAL=name, LEVEL=y [, PPC=n]      in a step: data x1, x2 (3D: x1, z1, x2, z2)
!>   *NONLOCAL, LENGTH=l [, VARIABLE=FVn] [, MATERIAL=name]   model data: scene_mpm_nonlocal
!>
!> Rigid surfaces are walls too: *SURFACE, TYPE=SEGMENTS (2D) or any 3D rigid surface (PLANE,
!> REVOLUTION, ...) (+ *RIGID BODY on a *NODE moved by *BOUNDARY) paired with the particles by
!> *CONTACT PAIR with a blank first field
!> (attach_surface_walls appends them to the walls; src/mpm/mpm_walls.f90 evaluates them).
!>
!> A scene with *MPM GRID is a material-point scene: it has no *ELEMENT mesh; its
!> materials, amplitudes, steps (*DYNAMIC, EXPLICIT, *DLOAD GRAV, *OUTPUT) are the usual ones.
!> "Up" is +y (axis 2) in 2D and 3D. The checks end with `file:line: what; expected ...`.
module scene_mpm
  use, intrinsic :: iso_fortran_env, only: int64
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t, keyword_block_t, data_line_t
  use model, only: model_t
  use mpm_scene, only: mpm_scene_t, particle_region_t, mpm_wall_t, mpm_step_t, shape_linear, &
       shape_gimp, region_box, region_polygon, wall_friction, wall_symmetry, wall_name_length
  use scene_layout, only: scene_layout_t
  use scene_materials, only: find_material
  use scene_mpm_side, only: read_side_friction
  use scene_mpm_decomposition, only: read_decomposition
  use scene_mpm_controls, only: read_mpm_controls
  use scene_mpm_nonlocal, only: read_nonlocal
  use scene_mpm_wall_open, only: read_wall_open
  use scene_util, only: itoa, rtoa, get_real, expect_lines, expect_fields, last_field, where_text, &
       check_name
  implicit none
  private

  public :: is_mpm_scene, check_mpm_keywords, build_mpm, mpm_keyword, mpm_has_nodes, attach_surface_walls

contains

  !> Is `name` one of the MPM keywords?
  pure logical function mpm_keyword(name)
    character(len=*), intent(in) :: name
    select case (name)
    case ('MPM GRID', 'MPM CONTROLS', 'PARTICLES', 'MPM WALL', 'OUTFLOW', 'INFLOW', 'MPM SIDE FRICTION', 'NONLOCAL')
       mpm_keyword = .true.
    case default
       mpm_keyword = .false.
    end select
  end function mpm_keyword

  !> Block index of the *MPM GRID of the deck (0: not an MPM scene).
  pure integer function is_mpm_scene(deck)
    type(keyword_deck_t), intent(in) :: deck
    integer :: i
    is_mpm_scene = 0
    do i = 1, deck%n_blocks
       if (deck%blocks(i)%name == 'MPM GRID') then
          is_mpm_scene = i
          return
       end if
    end do
  end function is_mpm_scene

  !> MPM keywords need *MPM GRID; an MPM scene takes no mesh keywords (no FEM-MPM coupling yet),
  !> but rigid surfaces with their reference nodes, interactions, contact pairs and *BOUNDARY.
  subroutine check_mpm_keywords(deck, grid_block, err)
    type(keyword_deck_t), intent(in) :: deck
    integer, intent(in) :: grid_block
    type(error_t), intent(inout) :: err
    integer :: i
    character(len=:), allocatable :: stype

    do i = 1, deck%n_blocks
       associate (blk => deck%blocks(i))
         if (grid_block == 0) then
            if (mpm_keyword(blk%name)) then
               call blk%fail('*' // blk%name // ' without *MPM GRID; expected *MPM GRID, CELL=h in a ' // &
                    'material-point scene', err)
               return
            end if
         else
            select case (blk%name)
            case ('ELEMENT', 'ELSET', 'SOLID SECTION', 'SECTION CONTROLS')
               call blk%fail('*' // blk%name // ' in a material-point scene (*MPM GRID at ' // &
                    where_text(deck%blocks(grid_block)%file, deck%blocks(grid_block)%line) // &
                    '); expected MPM keywords (*PARTICLES, *MPM WALL, ...): meshes and MPM do not mix yet', err)
               return
            case ('SURFACE')
               ! rigid surfaces (walls) only: there are no element faces
               if (blk%has_param('TYPE')) then
                  call blk%get_string('TYPE', stype, err)
                  if (err%raised) return
               else
                  stype = 'ELEMENT'
               end if
               if (stype == 'ELEMENT') then
                  call blk%fail('*SURFACE, TYPE=ELEMENT in a material-point scene; expected TYPE=SEGMENTS ' // &
                       '(2D) or TYPE=PLANE, REVOLUTION, CYLINDER, FACETS (3D): a rigid surface paired with ' // &
                       'the particles by *CONTACT PAIR', err)
                  return
               end if
            case ('MPM GRID')
               if (i /= grid_block) then
                  call blk%fail('second *MPM GRID (first at ' // where_text(deck%blocks(grid_block)%file, &
                       deck%blocks(grid_block)%line) // '); expected one grid per scene', err)
                  return
               end if
            end select
         end if
       end associate
    end do
  end subroutine check_mpm_keywords

  !> Build model%mpm from the deck (after materials, before steps).
  subroutine build_mpm(deck, layout, grid_block, model, err)
    type(keyword_deck_t), intent(in) :: deck
    type(scene_layout_t), intent(in) :: layout
    integer, intent(in) :: grid_block
    type(model_t), intent(inout) :: model
    type(error_t), intent(inout) :: err
    integer :: i, s, nsteps
    type(mpm_step_t) :: carry

    associate (mpm => model%mpm)
      mpm%active = .true.
      call read_grid(deck%blocks(grid_block), mpm, err)
      if (err%raised) return
      model%mesh%ndim = mpm%ndim
      nsteps = layout%n_steps
      allocate (mpm%regions(0), mpm%walls(0), mpm%steps(max(nsteps, 1)))
      ! model data
      do i = 1, deck%n_blocks
         if (layout%step_of(i) /= 0) cycle
         associate (blk => deck%blocks(i))
           select case (blk%name)
           case ('MPM CONTROLS')
              call read_mpm_controls(blk, carry, err)
              if (.not. err%raised) call read_decomposition(blk, mpm, err)
           case ('MPM SIDE FRICTION')
              call read_side_friction(blk, mpm%ndim, carry, err)
           case ('PARTICLES')
              call read_particles(blk, model, err)
           case ('MPM WALL')
              call read_wall(blk, mpm, 0, max(nsteps, 1), err)
           case ('OUTFLOW')
              call read_outflow(blk, mpm, err)
           case ('NONLOCAL')
              call read_nonlocal(blk, model, err)
           case ('INFLOW')
              call blk%fail('*INFLOW outside a step; expected it inside the step where material flows in', err)
           end select
           if (err%raised) return
         end associate
      end do
      if (size(mpm%regions) == 0) then
         call deck%blocks(grid_block)%fail('material-point scene without *PARTICLES; expected at least ' // &
              'one *PARTICLES, MATERIAL=...', err)
         return
      end if
      call check_mpm_size(deck%blocks(grid_block), mpm, err)
      if (err%raised) return
      ! steps: controls carry over; inflow belongs to its step; walls from their step on
      do s = 1, nsteps
         carry%inflow%on = .false.
         do i = layout%step_block(s) + 1, layout%end_block(s) - 1
            associate (blk => deck%blocks(i))
              select case (blk%name)
              case ('MPM CONTROLS')
                 call read_mpm_controls(blk, carry, err)
                 if (.not. err%raised .and. (blk%has_param('DECOMPOSITION') .or. blk%has_param('REBALANCE'))) &
                      call blk%fail('DECOMPOSITION/REBALANCE in a step; expected them in the model data', err)
              case ('MPM SIDE FRICTION')
                 call read_side_friction(blk, mpm%ndim, carry, err)
              case ('MPM WALL')
                 call read_wall(blk, mpm, s, nsteps, err)
              case ('INFLOW')
                 call read_inflow(blk, model, carry, err)
              case ('PARTICLES', 'OUTFLOW', 'MPM GRID', 'NONLOCAL')
                 call blk%fail('*' // blk%name // ' inside a step; expected it in the model data ' // &
                      '(before the first *STEP)', err)
              end select
              if (err%raised) return
            end associate
         end do
         mpm%steps(s) = carry
      end do
    end associate
  end subroutine build_mpm

  subroutine read_grid(blk, mpm, err)
    type(keyword_block_t), intent(in) :: blk
    type(mpm_scene_t), intent(inout) :: mpm
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: shape
    integer :: n0, n1, k

    call blk%check_params([character(len=8) :: 'CELL', 'SHAPE'], err)
    if (.not. err%raised) call blk%get_real('CELL', mpm%cell, err, minimum=tiny(1.0_dp))
    if (.not. err%raised) call blk%get_string('SHAPE', shape, err, default='GIMP', choices=[character(len=6) :: &
         'GIMP', 'LINEAR'])
    if (.not. err%raised) call expect_lines(blk, 2, 2, 'two lines: the low corner x, y[, z] and the high ' // &
         'corner of the grid', err)
    if (err%raised) return
    mpm%shape = shape_gimp
    if (shape == 'LINEAR') mpm%shape = shape_linear
    n0 = last_field(blk%lines(1))
    n1 = last_field(blk%lines(2))
    if (n0 < 2 .or. n0 > 3 .or. n1 /= n0) then
       call raise_error(blk%lines(2)%file, blk%lines(2)%line, 'grid corners have ' // itoa(n0) // ' and ' // &
            itoa(n1) // ' values; expected x, y (2D plane strain) or x, y, z (3D) on both lines', err)
       return
    end if
    mpm%ndim = n0
    do k = 1, n0
       call get_real(blk%lines(1), k, mpm%lo(k), err)
       if (.not. err%raised) call get_real(blk%lines(2), k, mpm%hi(k), err)
       if (err%raised) return
       if (mpm%hi(k) - mpm%lo(k) < 4 * mpm%cell) then
          call raise_error(blk%lines(2)%file, blk%lines(2)%line, 'grid extent ' // &
               rtoa(mpm%hi(k) - mpm%lo(k)) // ' along axis ' // itoa(k) // ' is less than 4 cells of ' // &
               rtoa(mpm%cell) // '; expected high corner > low corner + 4 CELL', err)
          return
       end if
    end do
  end subroutine read_grid

  !> The grid's node count and the particles of the regions, counted in floating point (they are
  !> products of counts per axis: a small CELL overflowed the 32-bit node count and the run
  !> crashed), against what the solver indexes (32-bit counts) and what the machine has: the
  !> grid and particle arrays alone (a lower bound of the run's memory, on every rank: each
  !> holds the whole grid) must fit in its physical memory. Said with the figures, at *MPM GRID.
  subroutine check_mpm_size(blk, mpm, err)
    type(keyword_block_t), intent(in) :: blk
    type(mpm_scene_t), intent(in) :: mpm
    type(error_t), intent(inout) :: err
    real(dp) :: nodes, particles, count, bytes, memory, dx
    real(dp), parameter :: index_limit = 2147483647.0_dp
    integer :: k, i, nd, ncomp
    character(len=40) :: figure

    nd = mpm%ndim
    ncomp = merge(4, 6, nd == 2)
    nodes = 1
    do k = 1, nd
       nodes = nodes * (real(ceiling((mpm%hi(k) - mpm%lo(k)) / mpm%cell - 1.0e-9_dp, int64), dp) + 1)
    end do
    particles = 0
    do i = 1, size(mpm%regions)
       dx = mpm%cell / mpm%regions(i)%ppc
       count = 1
       do k = 1, nd
          count = count * (real(ceiling((mpm%regions(i)%hi(k) - mpm%lo(k)) / dx, int64) - &
               floor((mpm%regions(i)%lo(k) - mpm%lo(k)) / dx, int64), dp) + 1)
       end do
       particles = particles + count
    end do
    if (nodes > index_limit) then
       write (figure, '(es10.3)') nodes
       call blk%fail('*MPM GRID, CELL=' // rtoa(mpm%cell) // ' makes ' // trim(adjustl(figure)) // ' grid nodes, ' // &
            'more than the 2147483647 a run indexes; expected a larger CELL or a smaller grid', err)
       return
    end if
    if (particles > index_limit) then
       write (figure, '(es10.3)') particles
       call blk%fail('the *PARTICLES regions of this grid (CELL=' // rtoa(mpm%cell) // ') hold ' // &
            trim(adjustl(figure)) // ' particles, more than the 2147483647 a run indexes; expected a ' // &
            'larger CELL, a smaller PPC or smaller regions', err)
       return
    end if
    ! grid: mass, own mass, momentum, force, two velocities, active flag; particles: position,
    ! velocity, stress, deformation gradient, mass and volume (8-byte reals)
    bytes = nodes * (8 * (2 + 4 * nd) + 4) + particles * 8 * (2 * nd + ncomp + nd * nd + 2)
    memory = physical_memory()
    if (memory > 0 .and. bytes > memory) then
       write (figure, '(f0.1,a,f0.1,a)') bytes / 2.0_dp**30, ' GiB; the machine has ', memory / 2.0_dp**30, ' GiB'
       call blk%fail('*MPM GRID, CELL=' // rtoa(mpm%cell) // ': the grid (' // itoa(int(nodes)) // ' nodes) and ' // &
            'the particles (' // itoa(int(particles)) // ') need at least ' // trim(figure) // &
            '; expected a larger CELL or a smaller grid', err)
    end if
  end subroutine check_mpm_size

  !> The machine's physical memory in bytes (MemTotal of /proc/meminfo), 0 when unknown.
  real(dp) function physical_memory() result(bytes)
    character(len=256) :: line
    integer :: unit, ios
    real(dp) :: kib

    bytes = 0
    open (newunit=unit, file='/proc/meminfo', status='old', action='read', iostat=ios)
    if (ios /= 0) return
    do
       read (unit, '(a)', iostat=ios) line
       if (ios /= 0) exit
       if (line(1:9) == 'MemTotal:') then
          read (line(10:), *, iostat=ios) kib
          if (ios == 0) bytes = 1024 * kib
          exit
       end if
    end do
    close (unit)
  end function physical_memory

  subroutine material_param(blk, model, k, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(in) :: model
    integer, intent(out) :: k
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: name

    k = 0
    call blk%get_string('MATERIAL', name, err)
    if (err%raised) return
    k = find_material(model, name)
    if (k == 0) call blk%fail('material ' // name // ' is not defined; expected the name of a *MATERIAL', err)
  end subroutine material_param

  subroutine read_particles(blk, model, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(inout) :: model
    type(error_t), intent(inout) :: err
    type(particle_region_t) :: r
    type(particle_region_t), allocatable :: grown(:)
    character(len=:), allocatable :: kind
    integer :: nd, k, il, n

    nd = model%mpm%ndim
    call blk%check_params([character(len=8) :: 'MATERIAL', 'PPC', 'TYPE', 'Z1', 'Z2', 'VX', 'VY', 'VZ'], err)
    if (.not. err%raised) call material_param(blk, model, r%material, err)
    if (.not. err%raised) call blk%get_integer('PPC', r%ppc, err, default=2, minimum=1, maximum=8)
    if (.not. err%raised) call blk%get_string('TYPE', kind, err, default='BOX', choices=[character(len=7) :: &
         'BOX', 'POLYGON'])
    if (.not. err%raised) call blk%get_real('VX', r%velocity(1), err, default=0.0_dp)
    if (.not. err%raised) call blk%get_real('VY', r%velocity(2), err, default=0.0_dp)
    if (.not. err%raised) call blk%get_real('VZ', r%velocity(3), err, default=0.0_dp)
    if (err%raised) return
    if (nd == 2 .and. (blk%has_param('Z1') .or. blk%has_param('Z2') .or. blk%has_param('VZ'))) then
       call blk%fail('*PARTICLES: Z1, Z2 and VZ belong to 3D grids; expected them only with a 3D *MPM GRID', err)
       return
    end if
    r%source = where_text(blk%file, blk%line)
    if (kind == 'BOX') then
       r%kind = region_box
       call expect_lines(blk, 2, 2, 'two lines: the low and the high corner of the box', err)
       if (err%raised) return
       do il = 1, 2
          call expect_fields(blk, blk%lines(il), nd, nd, 'x, y' // trim(merge(', z', '   ', nd == 3)), err)
          if (err%raised) return
       end do
       do k = 1, nd
          call get_real(blk%lines(1), k, r%lo(k), err)
          if (.not. err%raised) call get_real(blk%lines(2), k, r%hi(k), err)
          if (err%raised) return
          if (.not. (r%hi(k) > r%lo(k))) then
             call raise_error(blk%lines(2)%file, blk%lines(2)%line, 'box high corner is not above the low ' // &
                  'corner along axis ' // itoa(k) // '; expected hi > lo', err)
             return
          end if
       end do
    else
       r%kind = region_polygon
       call expect_lines(blk, 3, huge(1), 'at least three vertices x, y (one per line)', err)
       if (err%raised) return
       n = blk%n_lines
       allocate (r%polygon(2, n))
       do il = 1, n
          call expect_fields(blk, blk%lines(il), 2, 2, 'a vertex x, y', err)
          if (.not. err%raised) call get_real(blk%lines(il), 1, r%polygon(1, il), err)
          if (.not. err%raised) call get_real(blk%lines(il), 2, r%polygon(2, il), err)
          if (err%raised) return
       end do
       r%lo(1:2) = minval(r%polygon, dim=2)
       r%hi(1:2) = maxval(r%polygon, dim=2)
       if (nd == 3) then
          call blk%get_real('Z1', r%lo(3), err)
          if (.not. err%raised) call blk%get_real('Z2', r%hi(3), err)
          if (err%raised) return
          if (.not. (r%hi(3) > r%lo(3))) then
             call blk%fail('*PARTICLES: Z2 must exceed Z1; expected the z range of the extruded polygon', err)
             return
          end if
       end if
    end if
    do k = 1, nd
       if (r%lo(k) < model%mpm%lo(k) + model%mpm%cell .or. r%hi(k) > model%mpm%hi(k) - model%mpm%cell) then
          call blk%fail('*PARTICLES region reaches beyond the grid less one cell along axis ' // itoa(k) // &
               '; expected it inside [' // rtoa(model%mpm%lo(k) + model%mpm%cell) // ', ' // &
               rtoa(model%mpm%hi(k) - model%mpm%cell) // ']', err)
          return
       end if
    end do
    n = size(model%mpm%regions)
    allocate (grown(n + 1))
    grown(1:n) = model%mpm%regions
    grown(n + 1) = r
    call move_alloc(grown, model%mpm%regions)
  end subroutine read_particles

  !> *MPM WALL in model data (step 0: active in all steps) or in step s (active from s on);
  !> OP=DELETE ends an existing wall at step s.
  subroutine read_wall(blk, mpm, s, nsteps, err)
    type(keyword_block_t), intent(in) :: blk
    type(mpm_scene_t), intent(inout) :: mpm
    integer, intent(in) :: s, nsteps
    type(error_t), intent(inout) :: err
    type(mpm_wall_t) :: w
    type(mpm_wall_t), allocatable :: grown(:)
    character(len=:), allocatable :: name, kind, op
    integer :: nd, k, n, found
    real(dp) :: t(3), length

    nd = mpm%ndim
    call blk%check_params([character(len=8) :: 'NAME', 'TYPE', 'FRICTION', 'OP', 'REACH', 'OPEN'], err)
    if (.not. err%raised) call blk%get_string('NAME', name, err)
    if (.not. err%raised) call check_name(blk, 'wall', name, wall_name_length, err)
    if (.not. err%raised) call blk%get_string('OP', op, err, default='NEW', choices=[character(len=6) :: &
         'NEW', 'DELETE'])
    if (err%raised) return
    found = 0
    do k = 1, size(mpm%walls)
       if (mpm%walls(k)%name == name) found = k
    end do
    if (op == 'DELETE') then
       if (s == 0) then
          call blk%fail('*MPM WALL, OP=DELETE in model data; expected it inside the step from which the ' // &
               'wall is gone', err)
       else if (found == 0) then
          call blk%fail('*MPM WALL, OP=DELETE: wall ' // name // ' is not defined; expected the NAME of an ' // &
               'earlier *MPM WALL', err)
       else if (blk%has_param('TYPE') .or. blk%has_param('FRICTION') .or. blk%has_param('REACH') .or. &
            blk%has_param('OPEN') .or. blk%n_lines > 0) then
          call blk%fail('*MPM WALL, OP=DELETE takes only NAME; expected no TYPE, FRICTION, REACH, OPEN or data ' // &
               'lines', err)
       else
          mpm%walls(found)%active(s:) = .false.
       end if
       return
    end if
    if (found /= 0) then
       call blk%fail('wall ' // name // ' defined twice (first at ' // trim(mpm%walls(found)%source) // &
            '); expected unique wall names (OP=DELETE ends a wall)', err)
       return
    end if
    w%name = name
    w%source = where_text(blk%file, blk%line)
    call blk%get_string('TYPE', kind, err, default='FRICTION', choices=[character(len=8) :: 'FRICTION', 'SYMMETRY'])
    if (.not. err%raised) call blk%get_real('FRICTION', w%friction, err, default=0.0_dp, minimum=0.0_dp)
    if (.not. err%raised) call blk%get_real('REACH', w%reach, err, default=0.0_dp, minimum=0.0_dp, maximum=0.99_dp)
    if (err%raised) return
    w%kind = wall_friction
    if (kind == 'SYMMETRY') then
       w%kind = wall_symmetry
       if (blk%has_param('FRICTION')) then
          call blk%fail('*MPM WALL, TYPE=SYMMETRY with FRICTION; expected no friction on a symmetry plane', err)
          return
       end if
    end if
    if (nd == 2) then
       call expect_lines(blk, 1, 1, 'one line x0, y0, x1, y1 (the material on the left of p0 -> p1)', err)
       if (.not. err%raised) call expect_fields(blk, blk%lines(1), 4, 4, 'x0, y0, x1, y1', err)
       if (err%raised) return
       do k = 1, 2
          call get_real(blk%lines(1), k, w%p0(k), err)
          if (.not. err%raised) call get_real(blk%lines(1), 2 + k, w%p1(k), err)
          if (err%raised) return
       end do
       t = w%p1 - w%p0
       length = norm2(t)
       if (.not. (length > 0)) then
          call raise_error(blk%lines(1)%file, blk%lines(1)%line, 'wall segment has zero length; expected ' // &
               'two distinct points', err)
          return
       end if
       w%normal = [-t(2), t(1), 0.0_dp] / length
    else
       call expect_lines(blk, 1, 3, 'px, py, pz, nx, ny, nz [then the low and high corner of the wall''s box]', err)
       if (err%raised) return
       if (blk%n_lines == 2) then
          call blk%fail('*MPM WALL box needs two lines (low and high corner); expected 1 or 3 data lines', err)
          return
       end if
       call expect_fields(blk, blk%lines(1), 6, 6, 'px, py, pz, nx, ny, nz', err)
       if (err%raised) return
       do k = 1, 3
          call get_real(blk%lines(1), k, w%p0(k), err)
          if (.not. err%raised) call get_real(blk%lines(1), 3 + k, w%normal(k), err)
          if (err%raised) return
       end do
       length = norm2(w%normal)
       if (.not. (length > 0)) then
          call raise_error(blk%lines(1)%file, blk%lines(1)%line, 'wall normal is zero; expected a non-zero ' // &
               'normal nx, ny, nz pointing into the material', err)
          return
       end if
       w%normal = w%normal / length
       if (blk%n_lines == 3) then
          w%bounded = .true.
          do k = 1, 3
             call get_real(blk%lines(2), k, w%lo(k), err)
             if (.not. err%raised) call get_real(blk%lines(3), k, w%hi(k), err)
             if (err%raised) return
          end do
       end if
    end if
    call read_wall_open(blk, nd, kind == 'SYMMETRY', w, err)
    if (err%raised) return
    allocate (w%active(nsteps))
    w%active = .false.
    w%active(max(s, 1):) = .true.
    n = size(mpm%walls)
    allocate (grown(n + 1))
    grown(1:n) = mpm%walls
    grown(n + 1) = w
    call move_alloc(grown, mpm%walls)
  end subroutine read_wall

  subroutine read_outflow(blk, mpm, err)
    type(keyword_block_t), intent(in) :: blk
    type(mpm_scene_t), intent(inout) :: mpm
    type(error_t), intent(inout) :: err

    call blk%check_params([character(len=8) :: 'BELOW'], err)
    if (.not. err%raised) call blk%get_real('BELOW', mpm%outflow_level, err)
    if (.not. err%raised) call expect_lines(blk, 0, 0, 'no data lines', err)
    if (err%raised) return
    if (mpm%outflow) then
       call blk%fail('second *OUTFLOW; expected one outflow level per scene', err)
       return
    end if
    ! The removed particles must still have a full stencil inside the grid.
    if (mpm%outflow_level < mpm%lo(2) + 3 * mpm%cell) then
       call blk%fail('*OUTFLOW, BELOW=' // rtoa(mpm%outflow_level) // ' is less than 3 cells above the ' // &
            'bottom of the grid; expected BELOW >= ' // rtoa(mpm%lo(2) + 3 * mpm%cell), err)
       return
    end if
    mpm%outflow = .true.
  end subroutine read_outflow

  subroutine read_inflow(blk, model, c, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(in) :: model
    type(mpm_step_t), intent(inout) :: c
    type(error_t), intent(inout) :: err
    integer :: nd, k

    nd = model%mpm%ndim
    call blk%check_params([character(len=8) :: 'MATERIAL', 'LEVEL', 'PPC'], err)
    if (.not. err%raised) call material_param(blk, model, c%inflow%material, err)
    if (.not. err%raised) call blk%get_real('LEVEL', c%inflow%level, err)
    if (.not. err%raised) call blk%get_integer('PPC', c%inflow%ppc, err, default=2, minimum=1, maximum=8)
    if (.not. err%raised) call expect_lines(blk, 1, 1, trim(merge('x1, x2        ', 'x1, z1, x2, z2', nd == 2)) // &
         ' (the band where material flows in)', err)
    if (err%raised) return
    c%inflow%lo = 0
    c%inflow%hi = 0
    if (nd == 2) then
       call expect_fields(blk, blk%lines(1), 2, 2, 'x1, x2', err)
       if (.not. err%raised) call get_real(blk%lines(1), 1, c%inflow%lo(1), err)
       if (.not. err%raised) call get_real(blk%lines(1), 2, c%inflow%hi(1), err)
    else
       call expect_fields(blk, blk%lines(1), 4, 4, 'x1, z1, x2, z2', err)
       if (.not. err%raised) call get_real(blk%lines(1), 1, c%inflow%lo(1), err)
       if (.not. err%raised) call get_real(blk%lines(1), 2, c%inflow%lo(3), err)
       if (.not. err%raised) call get_real(blk%lines(1), 3, c%inflow%hi(1), err)
       if (.not. err%raised) call get_real(blk%lines(1), 4, c%inflow%hi(3), err)
    end if
    if (err%raised) return
    do k = 1, nd
       if (k == 2) cycle
       if (.not. (c%inflow%hi(k) > c%inflow%lo(k))) then
          call raise_error(blk%lines(1)%file, blk%lines(1)%line, '*INFLOW band is empty along axis ' // &
               itoa(k) // '; expected the second coordinate above the first', err)
          return
       end if
    end do
    if (c%inflow%level > model%mpm%hi(2) - 2 * model%mpm%cell) then
       call blk%fail('*INFLOW, LEVEL=' // rtoa(c%inflow%level) // ' is within 2 cells of the top of the ' // &
            'grid; expected LEVEL <= ' // rtoa(model%mpm%hi(2) - 2 * model%mpm%cell), err)
       return
    end if
    c%inflow%on = .true.
  end subroutine read_inflow

  !> Does the deck name nodes (reference nodes of rigid bodies, their sets or conditions)?
  pure logical function mpm_has_nodes(deck)
    type(keyword_deck_t), intent(in) :: deck
    integer :: i
    mpm_has_nodes = .false.
    do i = 1, deck%n_blocks
       select case (deck%blocks(i)%name)
       case ('NODE', 'NSET', 'RIGID BODY', 'BOUNDARY')
          mpm_has_nodes = .true.
       end select
    end do
  end function mpm_has_nodes

  !> The rigid surfaces the steps pair with the particles (*CONTACT PAIR with a blank first
  !> field) become walls of the MPM scene, after the *MPM WALLs: one wall per surface, named
  !> after it, active in the steps whose pairs name it, with the friction of its interaction.
  !> Every node of the scene must be a rigid body's reference node (nothing else has nodes).
  subroutine attach_surface_walls(deck, layout, model, err)
    type(keyword_deck_t), intent(in) :: deck
    type(scene_layout_t), intent(in) :: layout
    type(model_t), intent(inout) :: model
    type(error_t), intent(inout) :: err
    type(mpm_wall_t), allocatable :: walls(:)
    integer :: s, j, r, k, n0, nsteps
    integer, allocatable :: wall_of(:)
    real(dp) :: mu

    call check_reference_nodes(deck, layout, model, err)
    if (err%raised) return
    nsteps = max(model%n_steps, 1)
    allocate (wall_of(model%n_rigid_surfaces))
    wall_of = 0
    n0 = size(model%mpm%walls)
    allocate (walls, source=model%mpm%walls)
    do s = 1, model%n_steps
       if (.not. allocated(model%steps(s)%contact_pairs)) cycle
       do j = 1, size(model%steps(s)%contact_pairs)
          associate (cp => model%steps(s)%contact_pairs(j))
            r = cp%rigid_surface
            mu = 0
            if (cp%interaction > 0) mu = model%interactions(cp%interaction)%friction
            if (wall_of(r) == 0) then
               do k = 1, n0
                  if (walls(k)%name == model%rigid_surfaces(r)%name) then
                     call deck%blocks(1)%fail('rigid surface ' // trim(model%rigid_surfaces(r)%name) // &
                          ' has the name of *MPM WALL ' // trim(walls(k)%name) // ' (' // trim(walls(k)%source) // &
                          '); expected distinct wall names (they name the history columns)', err)
                     return
                  end if
               end do
               walls = [walls, mpm_wall_t(name=model%rigid_surfaces(r)%name, friction=mu, surface=r)]
               wall_of(r) = size(walls)
               allocate (walls(wall_of(r))%active(nsteps))
               walls(wall_of(r))%active = .false.
               walls(wall_of(r))%source = 'rigid surface ' // trim(model%rigid_surfaces(r)%name)
            else if (abs(walls(wall_of(r))%friction - mu) > 0) then
               call deck%blocks(layout%step_block(s))%fail('rigid surface ' // &
                    trim(model%rigid_surfaces(r)%name) // ' is paired with friction ' // rtoa(mu) // &
                    ' in step ' // trim(model%steps(s)%name) // ' and ' // rtoa(walls(wall_of(r))%friction) // &
                    ' before; expected one friction per rigid surface in a material-point scene', err)
               return
            end if
            walls(wall_of(r))%active(s) = .true.
          end associate
       end do
    end do
    call move_alloc(walls, model%mpm%walls)
  end subroutine attach_surface_walls

  !> In a material-point scene a node is a rigid body's reference node, or an error.
  subroutine check_reference_nodes(deck, layout, model, err)
    type(keyword_deck_t), intent(in) :: deck
    type(scene_layout_t), intent(in) :: layout
    type(model_t), intent(in) :: model
    type(error_t), intent(inout) :: err
    integer :: n, i

    do n = 1, model%mesh%n_nodes
       if (any(model%rigid_surfaces(1:model%n_rigid_surfaces)%ref_node == n)) cycle
       do i = 1, deck%n_blocks
          if (layout%step_of(i) == 0 .and. deck%blocks(i)%name == 'NODE') then
             call deck%blocks(i)%fail('node ' // itoa(model%mesh%node_id(n)) // ' is no *RIGID BODY ' // &
                  'reference node; expected only reference nodes of rigid surfaces in a material-point scene', err)
             return
          end if
       end do
    end do
  end subroutine check_reference_nodes
end module scene_mpm
